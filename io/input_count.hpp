// What is known about an input's triangle count while it is read: what its header promised,
// how many triangles the reader delivered so far and how many of those were dropped on the
// way (io::TriangleInput keeps it). Plain data, header-only, so a consumer that links none of
// io's codecs (the stream decimator) can follow it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>

namespace meshstream::io {

struct InputCount {
    std::optional<uint64_t> promised;  // the header's triangle count, when it states one
    uint64_t read = 0;                 // triangles the reader delivered so far
    uint64_t dropped = 0;              // of those, not passed on (non-finite, degenerate)

    uint64_t passed() const { return read - dropped; }
    // The most triangles the consumer can still be given in all: the promise less what was
    // dropped so far (never below what it was already given). nullopt without a promise.
    std::optional<uint64_t> usable() const {
        if (!promised) return std::nullopt;
        return std::max(passed(), *promised - std::min(*promised, dropped));
    }
};

}  // namespace meshstream::io
