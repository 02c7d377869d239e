// The sort key and the in-memory run sort of `meshstream sort`. A triangle's key is the
// minimum of its three corner coordinates along the sort axis, mapped to an unsigned integer
// whose order is the float order (the sign-flip trick of Terdiman's "Radix Sort Revisited" and
// Herf's "Radix Tricks"), so runs can be sorted by an LSD radix sort: stable, O(n), no
// comparisons. Why the minimum: a sweep front that has read every triangle with key < k knows
// that no later triangle has a corner below k, so vertices below the front are complete.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>

namespace meshstream::sort {

// Maps a float to a uint32 with the same order: a < b (as floats) implies key(a) < key(b).
// -0.0 and +0.0 map to the same key (they compare equal, so a stable sort keeps their input
// order); every NaN maps to 0xFFFFFFFF, above +infinity.
inline uint32_t ordered_key(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    if ((u & 0x7FFFFFFFu) > 0x7F800000u) return 0xFFFFFFFFu;  // NaN
    if ((u & 0x7FFFFFFFu) == 0) return 0x80000000u;           // ±0 → key of +0
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

// The inverse of ordered_key for non-NaN keys (for diagnostics and tests).
inline float key_to_float(uint32_t key) {
    uint32_t u = (key & 0x80000000u) ? (key & 0x7FFFFFFFu) : ~key;
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}

// The sort key of the triangle at `xyz` (9 floats: v0, v1, v2) along `axis` (0, 1 or 2): the
// smallest ordered_key of its three corners. A NaN corner is ignored unless all three are NaN.
inline uint32_t triangle_key(const float* xyz, int axis) {
    uint32_t a = ordered_key(xyz[axis]), b = ordered_key(xyz[3 + axis]), c = ordered_key(xyz[6 + axis]);
    uint32_t m = a < b ? a : b;
    return m < c ? m : c;
}

// The 30-bit Morton code of a cell of a 1024^3 grid (x, y, z each below 1024): their bits
// interleaved, x's highest (bit b of a coordinate to bit 3b, 3b+1, 3b+2 for z, y, x). Sorted
// by it, cells follow a Z-order curve: an octree's cells in depth-first order.
inline uint32_t morton30(uint32_t x, uint32_t y, uint32_t z) {
    auto spread = [](uint32_t v) {
        v = (v | v << 16) & 0x030000FFu;
        v = (v | v << 8) & 0x0300F00Fu;
        v = (v | v << 4) & 0x030C30C3u;
        return (v | v << 2) & 0x09249249u;
    };
    return spread(x) << 2 | spread(y) << 1 | spread(z);
}

// Stable LSD radix sort of `items` by their high 32 bits (the key); the low 32 bits are a
// payload (here: the triangle's position in the run), so equal keys keep their input order.
// `scratch` must have items.size() elements. Three passes of 11/11/10 bits; a pass whose
// digit is the same for every item is skipped. Returns the span (items or scratch) that holds
// the sorted sequence. Memory: none beyond the two spans (histograms on the stack).
std::span<uint64_t> radix_sort_by_key(std::span<uint64_t> items, std::span<uint64_t> scratch);

}  // namespace meshstream::sort
