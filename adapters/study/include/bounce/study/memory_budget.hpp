#pragma once
/// \file memory_budget.hpp
/// What a run may still allocate, so that programs refuse a size that cannot fit with the
/// figure, before the allocation that would abort with std::bad_alloc.

#include <cstdint>
#include <string>

namespace bounce::study {

/// Bytes this process can still allocate: the least of MemAvailable (/proc/meminfo; else
/// sysconf's available pages), the cgroup's memory.max less memory.current, and the address
/// space and data limits (ulimit -v, -d) less what the process has mapped already.
/// 0 when nothing is left or nothing can be read.
std::uint64_t available_memory_bytes();

/// "3.2 GB", "512 MB": a byte count for messages.
std::string format_bytes(double bytes);

}  // namespace bounce::study
