// The one place where meshstream's commands skip triangles that no consumer can use, so
// convert, sort and decimate apply the same policy (docs/robustness.md):
//   - a NaN or infinite coordinate (possible in binary STL/PLY/Draco and as "nan"/"inf" text);
//   - a degenerate face: two corners at exactly the same position (-0 == +0).
// Each is dropped and counted into a tools::Warnings line; with --strict the first one is an
// io::Error naming the file and the triangle's ordinal instead. Zero-area faces with three
// distinct corners (slivers) are kept: they are valid geometry that the decimator removes.
// Readers still reject what is malformed (indices out of range, truncation) themselves.
#pragma once

#include "io/chunk.hpp"
#include "tools/common.hpp"

#include <cstdint>
#include <string>

namespace meshstream::tools {

class TriangleFilter {
public:
    // `file` names the input in errors; `strict`: throw instead of skipping.
    TriangleFilter(std::string file, bool strict) : file_(std::move(file)), strict_(strict) {}

    // Removes the skipped triangles from `chunk` in place, keeping its channels aligned;
    // returns how many were removed. Throws io::Error under --strict. Call once per chunk,
    // in input order (the ordinal in errors counts every triangle seen).
    size_t apply(io::TriangleChunk& chunk);

    uint64_t non_finite() const { return non_finite_; }
    uint64_t degenerate() const { return degenerate_; }
    uint64_t skipped() const { return non_finite_ + degenerate_; }
    // Adds one counted line per kind that occurred.
    void report(Warnings& warnings) const;

private:
    std::string file_;
    bool strict_;
    uint64_t seen_ = 0;
    uint64_t non_finite_ = 0, degenerate_ = 0;
};

}  // namespace meshstream::tools
