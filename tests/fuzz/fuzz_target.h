#pragma once
// Shared by the fuzz targets: the libFuzzer entry point, and what counts as a finding. A target
// may throw caliber::Error (the documented answer to bad input); any other exception, a crash, a
// sanitizer report, a hang or running out of memory is a finding.

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
