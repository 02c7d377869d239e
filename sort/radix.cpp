// LSD radix sort on 32-bit keys packed above a 32-bit payload. One read pass builds all three
// histograms (Terdiman, "Radix Sort Revisited"), then each non-trivial digit is scattered once.
#include "sort/radix.hpp"

#include <cassert>
#include <cstddef>

namespace meshstream::sort {

std::span<uint64_t> radix_sort_by_key(std::span<uint64_t> items, std::span<uint64_t> scratch) {
    assert(scratch.size() == items.size());
    constexpr int kShift[3] = {32, 43, 54};
    constexpr uint32_t kMask[3] = {0x7FF, 0x7FF, 0x3FF};
    const size_t n = items.size();
    if (n < 2) return items;

    static_assert(sizeof(size_t) >= 4);
    size_t hist[3][2048] = {};
    for (uint64_t v : items)
        for (int d = 0; d < 3; ++d) ++hist[d][(v >> kShift[d]) & kMask[d]];

    uint64_t* src = items.data();
    uint64_t* dst = scratch.data();
    for (int d = 0; d < 3; ++d) {
        // All items share this digit: the pass would copy them in order, so skip it.
        if (hist[d][(src[0] >> kShift[d]) & kMask[d]] == n) continue;
        size_t offset[2048];
        size_t sum = 0;
        for (uint32_t b = 0; b <= kMask[d]; ++b) {
            offset[b] = sum;
            sum += hist[d][b];
        }
        const int shift = kShift[d];
        const uint32_t mask = kMask[d];
        for (size_t i = 0; i < n; ++i) {
            uint64_t v = src[i];
            dst[offset[(v >> shift) & mask]++] = v;
        }
        uint64_t* t = src;
        src = dst;
        dst = t;
    }
    return src == items.data() ? items : scratch;
}

}  // namespace meshstream::sort
