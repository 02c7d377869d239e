// Where a decimator's output goes: a callback handed each full chunk of output triangles.
#pragma once

#include "io/chunk.hpp"

#include <functional>

namespace meshstream::decimate {

// Receives each full chunk of output triangles (positions + vertex_id channel, plus the carried
// channels with an attribute layout); the chunk is reused after the call returns.
using Emit = std::function<void(const io::TriangleChunk&)>;

}  // namespace meshstream::decimate
