// Number formatting for the text writers (PLY ascii, OBJ): std::to_chars, so no locale and no
// iostreams, and floats come out in their shortest round-trip form. Also byte sizes for
// messages about --memory.
#pragma once

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <string>

namespace meshstream::io {

// Appends `v` (an integer or floating-point value) to `out` in std::to_chars' default form:
// decimal integers, shortest round-trip floats. Allocates only when `out` grows.
template <class N>
void append_number(std::string& out, N v) {
    char buf[32];
    out.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);  // shortest round-trip form
}

// A byte count in the binary units --memory is given in: "512 bytes", "98 KiB", "1.5 MiB",
// "64 MiB" (one decimal below 10 units unless exact; a small budget is not shown as "1 MiB").
inline std::string binary_size(uint64_t bytes) {
    const char* units[] = {"KiB", "MiB", "GiB", "TiB"};
    if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
    int u = 0;
    double scale = 1024;
    while (u < 3 && bytes >= scale * 1024) scale *= 1024, ++u;
    const double value = double(bytes) / scale;
    char buf[32];
    if (value < 10 && bytes % uint64_t(scale) != 0)
        std::snprintf(buf, sizeof buf, "%.1f %s", value, units[u]);
    else
        std::snprintf(buf, sizeof buf, "%.0f %s", value, units[u]);
    return buf;
}

}  // namespace meshstream::io
