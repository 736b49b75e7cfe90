// The wide CD tree's node tests (cd_tree.h): a visit's children at once, and a node alone.

#include "narrow/cd_tree.h"

#include "bvh/wide_tree.h"
#include "narrow/visit.h"

namespace caliber::narrow {

const detail::WideTest kWideTest =
    detail::wide_test_form(true) != nullptr ? detail::wide_test_form(true) : detail::wide_test_form(false);
const WideLoop kWideLoop = detail::wide_loop_form(true) != nullptr ? detail::wide_loop_form(true) : detail::wide_loop_form(false);
const detail::SlotOrderKeys kSlotOrderKeys = detail::slot_order_keys_avx2_if_supported();

void wide_lanes(const PairContext& ctx, detail::WideLanes& out) {
  detail::make_wide_lanes(ctx.node_test_frame(), ctx.lanes_scale(), ctx.a(), ctx.b(), out);
}

detail::WideLanes wide_lanes(const PairContext& ctx) {
  detail::WideLanes l;
  wide_lanes(ctx, l);
  return l;
}

bool root_test(const PairContext& ctx, NodePair n, RootTest how) {
  switch (how) {
    case RootTest::done:
      return true;
    case RootTest::as_root:
      return ctx.node_test(n.a, n.b);
    case RootTest::with_disks:
      return ctx.node_test_2x2_lane(n.a, n.b);
    case RootTest::child_of_a:
    case RootTest::child_of_b:
      break;
  }
  // As the wide parent's visit tests it: its own lane, the other lanes empty.
  const bool down_a = how == RootTest::child_of_a;
  const WideNode w = bvh::single_slot(down_a ? ctx.a() : ctx.b(), down_a ? n.a : n.b);
  const BvhNode& staying = down_a ? ctx.b().nodes[n.b] : ctx.a().nodes[n.a];
  const WideVisit v{&w, down_a ? n.b : n.a, down_a, &staying, (down_a ? ctx.a() : ctx.b()).nodes.data()};
  return (wide_pass(ctx, n, v, wide_lanes(ctx)) & 1u) != 0;
}

}  // namespace caliber::narrow
