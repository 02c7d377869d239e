// The key under which meshstream identifies a position exactly: a coordinate's float bits with
// -0.0 folded into +0.0 (they compare equal as floats, and scanners write both). Welding, edge
// counting and the order measure all use it, so "the same vertex" means one thing everywhere.
#pragma once

#include <bit>
#include <cstdint>

namespace meshstream::io {

inline uint32_t position_bits(float f) {
    const uint32_t b = std::bit_cast<uint32_t>(f);
    return b == 0x80000000u ? 0u : b;
}

// A position's three keys in one 128-bit value (x, y in `a`; z in `b`), ordered and hashable.
struct PositionKey {
    uint64_t a = 0, b = 0;
    static PositionKey of(const float* p) {
        return {uint64_t{position_bits(p[0])} << 32 | position_bits(p[1]), position_bits(p[2])};
    }
    bool operator==(const PositionKey&) const = default;
    auto operator<=>(const PositionKey&) const = default;
};

}  // namespace meshstream::io
