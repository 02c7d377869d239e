// The 64-bit hash finaliser of io's open-addressing tables (the welder's and mesh_index's):
// MurmurHash3's fmix64 (Appleby, MurmurHash3.cpp), a bijection that spreads every input bit
// over the low bits used as the table index.
#pragma once

#include <cstdint>

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

}  // namespace meshstream::io
