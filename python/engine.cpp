// caliber.Engine, caliber.Batch and caliber.broad_phase: the parallel engine over batches of poses,
// many motions and frames of many objects, and the broad phase alone.

#include <chrono>

#include "common.h"
#include "interrupts.h"

namespace caliber_python {
namespace {

using EngineClass = py::class_<caliber::Engine>;

/// Engine.query_many: the poses read (errors naming the side and row), then the batch with the GIL
/// released once.
PyBatch query_many(caliber::Engine& engine, const PyModel& a, const py::object& poses_a, const PyModel& b,
                   const py::object& poses_b, const caliber::QueryRequest& request, const std::string& order) {
  const caliber::QuaternionOrder o = parse_order(order);
  const SidePoses pa(poses_a, o, "poses_a"), pb(poses_b, o, "poses_b");
  caliber::BatchResult result;
  double ms = 0.0;
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    result = engine.query_many(*a.model, pa.poses, *b.model, pb.poses, request);
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  PyBatch batch(result);
  batch.batch_ms = ms;
  return batch;
}

/// A side's motions from its start and end poses (each as SidePoses reads them), the same count.
std::vector<caliber::SweptPose> motions_of(const SidePoses& start, const SidePoses& end, const char* side) {
  if (start.poses.size() != end.poses.size()) {
    throw caliber::Error(caliber::ErrorCode::bad_argument, std::string("end_") + side,
                         std::to_string(end.poses.size()) + " poses but start_" + side + " has " +
                             std::to_string(start.poses.size()) + " (a side's start and end give one pose per motion)");
  }
  std::vector<caliber::SweptPose> out(start.poses.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {start.poses[i], end.poses[i]};
  return out;
}

/// Engine.sweep_many: the motions read, then the sweeps with the GIL released once.
PySweeps sweep_many(caliber::Engine& engine, const PyModel& a, const py::object& start_a, const py::object& end_a,
                    const PyModel& b, const py::object& start_b, const py::object& end_b, double tolerance,
                    std::uint64_t max_queries, const std::string& order) {
  const caliber::QuaternionOrder o = parse_order(order);
  const std::vector<caliber::SweptPose> ma = motions_of({start_a, o, "start_a"}, {end_a, o, "end_a"}, "a");
  const std::vector<caliber::SweptPose> mb = motions_of({start_b, o, "start_b"}, {end_b, o, "end_b"}, "b");
  if (ma.size() != mb.size() && ma.size() != 1 && mb.size() != 1) {
    throw caliber::Error(caliber::ErrorCode::bad_argument, "start_b",
                         std::to_string(mb.size()) + " motions but start_a gives " + std::to_string(ma.size()) +
                             " (give both sides the same number, or one motion to a side that moves the same in every row)");
  }
  const caliber::SweepRequest request = sweep_request(tolerance, max_queries);
  std::vector<caliber::SweepResult> results;
  double ms = 0.0;
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    results = engine.sweep_many(*a.model, ma, *b.model, mb, request);
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  PySweeps sweeps(results);
  sweeps.sweep_ms = ms;
  return sweeps;
}

caliber::Frame make_frame(const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses, const IdPairs& pairs,
                          const caliber::QueryRequest& request) {
  caliber::Frame frame;
  frame.models = shared_models(models);
  frame.poses = poses;
  frame.pairs = object_pairs(pairs);
  frame.request = request;
  return frame;
}

std::string batch_repr(const PyBatch& b) {
  const auto n = static_cast<std::size_t>(b.hit.shape(0));
  std::size_t hits = 0;
  for (std::size_t i = 0; i < n; ++i) hits += b.hit.data()[i] ? 1 : 0;
  return (count_of(n, "entry", "entries") + ", " + count_of(hits, "hit") + ", " +
          count_of(static_cast<std::size_t>(b.entries.shape(0)), "pair"));
}

std::string engine_repr(const caliber::Engine& engine) {
  return ("method " + std::string(caliber::to_string(engine.options().method)) + ", " + count_of(engine.threads(), "thread"));
}

void bind_batches(EngineClass& cls) {
  std::apply(
      [&](auto&&... request) {
        cls.def(
            "query_many",
            [](caliber::Engine& engine, const PyModel& a, const py::object& poses_a, const PyModel& b, const py::object& poses_b,
               const std::string& kind, std::optional<double> tolerance, double angle, std::size_t max_pairs,
               const std::string& order, bool lowest_ids) {
              return query_many(engine, a, poses_a, b, poses_b, make_request(kind, tolerance, angle, max_pairs, lowest_ids),
                                order);
            },
            py::arg("a"), py::arg("poses_a"), py::arg("b"), py::arg("poses_b"), request..., py::kw_only(),
            py::arg("order") = "wxyz", py::arg("lowest_ids") = false,
            "Model a against model b at many poses, on this engine's threads: entry i is query(a, poses_a[i], b, "
            "poses_b[i], ...) bit for bit. Each side is one Pose (kept for every entry), a list of Poses, or an array of N "
            "x 4 x 4 matrices or N x 7 rows (translation, then the quaternion in `order`: 'wxyz' or 'xyzw'), float32 or "
            "float64. Returns a Batch.");
      },
      request_args());
  cls.def("sweep_many", &sweep_many, py::arg("a"), py::arg("start_a"), py::arg("end_a"), py::arg("b"), py::arg("start_b"),
          py::arg("end_b"), py::kw_only(), py::arg("tolerance") = 0.0, py::arg("max_queries") = 100000, py::arg("order") = "wxyz",
          "The swept query along many motions, on this engine's threads: row i is sweep(a, start_a[i], end_a[i], b, "
          "start_b[i], end_b[i], ...) bit for bit. Each of the four is one Pose, a list of Poses, or an array of N x 4 x 4 "
          "matrices or N x 7 rows (translation, then the quaternion in `order`); a side's start and end give the same "
          "number, and a side of one motion keeps it for every row. Heavy sweeps' queries are split across threads when "
          "few are left. Returns Sweeps.");
}

void bind_find_pairs(EngineClass& cls) {
  cls.def(
      "find_pairs",
      [](caliber::Engine& engine, const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses,
         const std::string& kind, std::optional<double> tolerance, const py::object& fixed_flags, const IdPairs& ignored) {
        const std::vector<bool> fixed = flags_of(fixed_flags, "fixed");
        caliber::Frame frame = make_frame(models, poses, {}, make_request(kind, tolerance, 30.0, 0, false));
        const std::vector<caliber::ObjectPair> skip = object_pairs(ignored);
        {
          py::gil_scoped_release release;
          engine.find_pairs(frame, fixed, skip);
        }
        return id_pairs(frame.pairs);
      },
      py::arg("models"), py::arg("poses"), py::arg("kind") = "interference", py::arg("tolerance") = py::none(), py::kw_only(),
      py::arg("fixed") = py::list(), py::arg("ignored") = IdPairs{},
      "The broad phase on this engine's threads: the object pairs (a < b, sorted) whose world boxes overlap within the "
      "query's reach (its tolerance for kind 'distance' or 'contact'), what step() takes. The same pairs as "
      "broad_phase(); the engine keeps its tree of boxes from call to call (refitted), so calls on the same objects "
      "moving a little are cheaper. fixed: one flag per object (pairs of two fixed objects skipped); ignored: pairs never "
      "reported.");
}

void bind_frames(EngineClass& cls) {
  cls.def(
      "sweep",
      [](caliber::Engine& engine, const std::vector<PyModel>& models, const std::vector<caliber::Pose>& start,
         const std::vector<caliber::Pose>& end, double tolerance, std::uint64_t max_queries, const py::object& fixed_flags,
         const IdPairs& ignored) {
        const std::vector<bool> fixed = flags_of(fixed_flags, "fixed");
        const auto shared = shared_models(models);
        const std::vector<caliber::ObjectPair> skip = object_pairs(ignored);
        const caliber::SweepRequest request = sweep_request(tolerance, max_queries);
        std::vector<caliber::PairSweep> swept;
        {
          py::gil_scoped_release release;
          swept = engine.sweep(shared, start, end, request, fixed, skip);
        }
        return swept_pairs(swept);
      },
      py::arg("models"), py::arg("start"), py::arg("end"), py::kw_only(), py::arg("tolerance") = 0.0,
      py::arg("max_queries") = 100000, py::arg("fixed") = py::list(), py::arg("ignored") = IdPairs{},
      "Continuous collision detection for many objects: object i moves from start[i] to end[i] (translation linear, "
      "rotation by slerp); every pair whose swept boxes overlap is swept (caliber.sweep), in parallel on this engine's "
      "threads. Returns [((a, b), Sweep)] for the pairs that are not free, sorted.");
  std::apply(
      [&](auto&&... request) {
        cls.def(
            "step",
            [](caliber::Engine& engine, const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses,
               const IdPairs& pairs, const std::string& kind, std::optional<double> tolerance, double angle,
               std::size_t max_pairs, bool lowest_ids) {
              const caliber::Frame frame =
                  make_frame(models, poses, pairs, make_request(kind, tolerance, angle, max_pairs, lowest_ids));
              caliber::StepResult s;
              {
                py::gil_scoped_release release;
                s = engine.step(frame);
              }
              return to_result(std::move(s.contacts), s.stats, s.limit_reached, frame.request.kind);
            },
            py::arg("models"), py::arg("poses"), py::arg("pairs"), request..., py::kw_only(), py::arg("lowest_ids") = false,
            "One frame: every listed object pair (a < b, sorted) tested. max_pairs > 0 stops each object pair at that "
            "many triangle pairs and sets limit_reached (1: does each pair touch at all?).");
      },
      request_args());
}

/// An engine of the default method on `threads` threads, for one call of the module-level batch
/// functions.
caliber::Engine engine_for(int threads) {
  caliber::EngineOptions options;
  options.threads = threads;
  return caliber::Engine(interruptible(options));
}

/// caliber.query_many and caliber.sweep_many: Engine(threads=threads)'s methods, on a new engine.
void bind_module_batches(py::module_& m) {
  std::apply(
      [&](auto&&... request) {
        m.def(
            "query_many",
            [](const PyModel& a, const py::object& poses_a, const PyModel& b, const py::object& poses_b, const std::string& kind,
               std::optional<double> tolerance, double angle, std::size_t max_pairs, const std::string& order, int threads,
               bool lowest_ids) {
              const caliber::QueryRequest query = make_request(kind, tolerance, angle, max_pairs, lowest_ids);
              caliber::Engine engine = engine_for(threads);
              return query_many(engine, a, poses_a, b, poses_b, query, order);
            },
            py::arg("a"), py::arg("poses_a"), py::arg("b"), py::arg("poses_b"), request..., py::kw_only(),
            py::arg("order") = "wxyz", py::arg("threads") = 0, py::arg("lowest_ids") = false,
            "Engine(threads=threads).query_many(...): model a against model b at many poses, in parallel, the GIL "
            "released once. Returns a Batch: per entry hit, distance, limit_reached; per reported pair a row with its "
            "entry.");
      },
      request_args());
  m.def(
      "sweep_many",
      [](const PyModel& a, const py::object& start_a, const py::object& end_a, const PyModel& b, const py::object& start_b,
         const py::object& end_b, double tolerance, std::uint64_t max_queries, const std::string& order, int threads) {
        caliber::Engine engine = engine_for(threads);
        return sweep_many(engine, a, start_a, end_a, b, start_b, end_b, tolerance, max_queries, order);
      },
      py::arg("a"), py::arg("start_a"), py::arg("end_a"), py::arg("b"), py::arg("start_b"), py::arg("end_b"), py::kw_only(),
      py::arg("tolerance") = 0.0, py::arg("max_queries") = 100000, py::arg("order") = "wxyz", py::arg("threads") = 0,
      "Engine(threads=threads).sweep_many(...): the swept query along many motions, in parallel, without the GIL. "
      "Returns Sweeps.");
}

}  // namespace

void bind_engine(py::module_& m) {
  bind_batch(m).def("__repr__", repr_of<PyBatch>("Batch", &batch_repr));
  EngineClass cls(m, "Engine", "The parallel engine: a method on the threads the process allows; keeps temporal state.");
  cls.def(py::init([](const std::string& method, int threads) {
            caliber::EngineOptions options;
            options.method = caliber::parse_method(method);
            options.threads = threads;
            return std::make_unique<caliber::Engine>(interruptible(options));
          }),
          py::arg("method") = std::string(caliber::to_string(caliber::kDefaultMethod)), py::arg("threads") = 0,
          "method: sequential, exploitation, stealing (the default), aposteriori, apriori or hybrid. threads: 0, every "
          "hardware thread the process may use (oneTBB's arena and limit); 1, the calling thread alone; N, at most N.")
      .def_property_readonly("threads", &caliber::Engine::threads)
      .def_property_readonly("method",
                             [](const caliber::Engine& e) { return std::string(caliber::to_string(e.options().method)); })
      .def("__repr__", repr_of<caliber::Engine>("Engine", &engine_repr))
      .def("__reduce__",
           [](const caliber::Engine&) -> py::object {
             throw not_picklable("Engine", "it holds temporal state and threads; make a new Engine where it is needed");
           })
      .def("forget", &caliber::Engine::forget);
  bind_batches(cls);
  bind_find_pairs(cls);
  bind_frames(cls);
  bind_module_batches(m);
  m.def(
      "broad_phase",
      [](const std::vector<PyModel>& models, const std::vector<caliber::Pose>& poses, double reach, const py::object& fixed_flags,
         const IdPairs& ignored) {
        const std::vector<bool> fixed = flags_of(fixed_flags, "fixed");
        const auto shared = shared_models(models);
        const std::vector<caliber::ObjectPair> skip = object_pairs(ignored);
        std::vector<caliber::ObjectPair> pairs;
        {
          py::gil_scoped_release release;
          pairs = caliber::broad_phase(shared, poses, reach, fixed, skip);
        }
        return id_pairs(pairs);
      },
      py::arg("models"), py::arg("poses"), py::arg("reach") = 0.0, py::arg("fixed") = py::list(), py::arg("ignored") = IdPairs{},
      "The object pairs (a < b, sorted) whose world boxes, grown by reach / 2, overlap: what Engine.step takes. fixed: "
      "one flag per object (pairs of two fixed objects are skipped); ignored: pairs never tested.");
}

}  // namespace caliber_python
