#pragma once
// Views of results for tests: a result's triangle pairs, and a query's contacts as a step's.

#include <cstdint>
#include <vector>

#include "caliber/query.h"
#include "narrow/candidate.h"

namespace caliber::test {

/// The triangle pairs of a result's contacts, in order.
inline std::vector<TrianglePair> pairs_of(const QueryResult& r) {
  std::vector<TrianglePair> out;
  out.reserve(r.contacts.size());
  for (const Contact& c : r.contacts) out.push_back(TrianglePair{c.tri_a, c.tri_b});
  return out;
}

/// Contacts of a query between objects a and b of a frame, as a step reports them.
inline std::vector<Contact> between(const QueryResult& r, std::uint32_t a, std::uint32_t b) {
  std::vector<Contact> out = r.contacts;
  for (Contact& c : out) {
    c.object_a = a;
    c.object_b = b;
  }
  return out;
}

}  // namespace caliber::test
