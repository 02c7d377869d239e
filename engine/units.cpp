// Counts and sizes in words: see units.hpp.
#include "engine/units.hpp"

#include <cstdio>

namespace meshstream::engine {

std::string human_count(double n, int significant_digits) {
    const char* unit = nullptr;
    double scaled = n;
    int decimals = 0;
    if (n >= 1e9)
        unit = "G", scaled = n / 1e9, decimals = 2;
    else if (n >= 1e6)
        unit = "M", scaled = n / 1e6, decimals = 2;
    else if (n >= 1e4)
        unit = "k", scaled = n / 1e3, decimals = 1;
    char buf[32];
    if (!unit)
        std::snprintf(buf, sizeof buf, "%.0f", n);
    else if (significant_digits > 0)
        std::snprintf(buf, sizeof buf, "%.*g %s", significant_digits, scaled, unit);
    else
        std::snprintf(buf, sizeof buf, "%.*f %s", decimals, scaled, unit);
    return buf;
}

std::string human_bytes(double bytes) {
    char buf[32];
    if (bytes >= 1e9)
        std::snprintf(buf, sizeof buf, "%.2f GB", bytes / 1e9);
    else if (bytes >= 1e6)
        std::snprintf(buf, sizeof buf, "%.1f MB", bytes / 1e6);
    else if (bytes >= 1e3)
        std::snprintf(buf, sizeof buf, "%.1f kB", bytes / 1e3);
    else
        std::snprintf(buf, sizeof buf, "%.0f B", bytes);
    return buf;
}

}  // namespace meshstream::engine
