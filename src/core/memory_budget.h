// How much memory a command may plan to use, checked before the large
// per-agent and per-frame buffers are allocated: a request beyond the budget
// is one clear error naming the figure, before any work starts, instead of
// a machine swapping for minutes. `--max-memory` sets it (default: 80 % of
// physical memory).
#pragma once

#include <cstdint>
#include <string>

namespace throng {

// Physical memory of this machine in bytes (0 when unknown).
std::uint64_t physical_memory_bytes();
// This process's resident set size in bytes, now (from /proc/self/statm; 0
// when unknown). What a long run watches for memory growth.
std::uint64_t resident_memory_bytes();
// The budget in bytes: the one set, else 80 % of physical memory (no limit
// when that is unknown).
std::uint64_t memory_budget();
// 0 restores the default.
void set_memory_budget(std::uint64_t bytes);

// "512M", "8G", "1.5GiB", "2000000" (bytes; K, M, G, T are powers of 1024).
// Throws Error naming `field` for anything else, zero or a negative size.
std::uint64_t parse_memory_size(const std::string& text, const std::string& field);
// 1536 -> "1.5 KiB"; for messages.
std::string format_bytes(double bytes);

// Throws Error at `field` when `bytes` exceed the budget: "about 7.2 GiB for
// 10000000 characters (760 bytes each) exceeds the memory budget of ...".
void check_memory_budget(double bytes, const std::string& what, const std::string& field);

}  // namespace throng
