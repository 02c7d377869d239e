// The decimator's pseudo-random generator: io::Rng (xoshiro256** seeded through splitmix64).
// Wu & Kobbelt 2003, §4.3/§4.4 draw their multiple-choice candidates at random; the generator
// is seeded from --seed and passed in, so the same input, options and seed give byte-identical
// output on every platform.
#pragma once

#include "io/random.hpp"

namespace meshstream::decimate {

using Rng = io::Rng;

}  // namespace meshstream::decimate
