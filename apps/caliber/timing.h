#pragma once
// The commands measure with the library's one clock (src/util/timing.h).

#include "util/timing.h"

namespace caliber::cli {

using util::Clock;
using util::median_of;
using util::ms_since;
using util::seconds_since;

}  // namespace caliber::cli
