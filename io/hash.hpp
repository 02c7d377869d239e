// The 64-bit hashing of io's open-addressing tables (the welder's and mesh_index's): the finaliser
// MurmurHash3's fmix64 (Appleby, MurmurHash3.cpp), a bijection that spreads every input bit
// over the low bits used as the table index, and a byte-record hash built on it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace meshstream::io {

// MurmurHash3's fmix64 of `h`. Pure and cheap (two multiplies); a bijection on uint64_t.
inline uint64_t mix64(uint64_t h) {
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    h ^= h >> 33;
    return h;
}

// n bytes at p folded 8 at a time into `h` through mix64 (a short tail is zero padded).
inline uint64_t hash_bytes(const std::byte* p, size_t n, uint64_t h = 0x9e3779b97f4a7c15ull) {
    for (size_t i = 0; i < n; i += 8) {
        uint64_t w = 0;
        std::memcpy(&w, p + i, std::min<size_t>(8, n - i));
        h = mix64(h ^ w);
    }
    return h;
}

}  // namespace meshstream::io
