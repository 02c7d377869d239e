// meshstream's pseudo-random generators, seeded and passed in, never global, so that the same
// input, options and seed give the same output on every platform (no rand(), no
// std::distributions, whose results differ between standard libraries).
// - SplitMix64 (Steele, Lea & Flood 2014): one 64-bit state; cheap to seed per item, so a
//   triangle's numbers can depend on the seed and its index only (compare's sampling, the
//   generator of test meshes).
// - Rng: xoshiro256** (Blackman & Vigna 2018) seeded through SplitMix64; the decimator's draws
//   (Wu & Kobbelt 2003, §4.3/§4.4: multiple-choice candidates).
#pragma once

#include <cstdint>

namespace meshstream::io {

struct SplitMix64 {
    uint64_t state = 0;

    uint64_t next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    // Uniform in [0, 1), 53 bits.
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
};

class Rng {
public:
    explicit Rng(uint64_t seed) {
        SplitMix64 s{seed};
        for (uint64_t& word : state_) word = s.next();
    }

    uint64_t next() {
        const uint64_t result = rotl(state_[1] * 5, 7) * 9;
        const uint64_t t = state_[1] << 17;
        state_[2] ^= state_[0];
        state_[3] ^= state_[1];
        state_[1] ^= state_[2];
        state_[0] ^= state_[3];
        state_[2] ^= t;
        state_[3] = rotl(state_[3], 45);
        return result;
    }

    // Uniform in [0, n) for n > 0 (Lemire's multiply-shift; the bias is below 2^-32).
    uint32_t below(uint32_t n) { return static_cast<uint32_t>(((next() >> 32) * static_cast<uint64_t>(n)) >> 32); }

private:
    static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
    uint64_t state_[4];
};

}  // namespace meshstream::io
