// Counts, sizes and times for messages and summaries: "1.23 M" triangles, "12.3 MB".
#pragma once

#include <chrono>
#include <string>

namespace meshstream::engine {

// n below 10^4 as an integer, above it scaled to k, M or G with a fixed number of decimals
// ("12.3 k", "1.23 M"), or, when `significant_digits` > 0, with that many significant digits
// ("500 k").
std::string human_count(double n, int significant_digits = 0);
// Decimal units: "512 B", "12.3 kB", "45.6 MB", "1.23 GB".
std::string human_bytes(double bytes);

// Seconds from `t` to now.
inline double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace meshstream::engine
