#pragma once
// The message of the caliber::Error a call throws, or "no error": for tests that check what an
// error says.

#include <string>

#include "caliber/error.h"

namespace caliber::test {

template <class F>
std::string error_message(F&& call) {
  try {
    (void)call();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace caliber::test
