#pragma once
/// \file
/// How much memory this process may still take: what the kernel says is available (MemAvailable),
/// and no more than the address-space limit (RLIMIT_AS, `ulimit -v`) leaves. Used to refuse work
/// that cannot fit before allocating it, with a message, instead of dying of std::bad_alloc.

#include <cstdint>
#include <string>

namespace caliber::util {

/// Bytes this process can still allocate, as far as the system tells (an estimate: other processes
/// may take memory meanwhile). UINT64_MAX when nothing can be read.
[[nodiscard]] std::uint64_t available_memory();

/// "1.5 GiB", "300 MiB": a byte count for messages.
[[nodiscard]] std::string format_bytes(double bytes);

}  // namespace caliber::util
