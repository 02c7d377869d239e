// Triangles as fixed-size records, the one codec for every place that stores chunks' triangles
// outside a chunk: the sort's runs (sort/external_sort.cpp), a spooled stdin and the ranges'
// spools of `decimate --threads`, the messages between MPI ranks and the part files of
// `decimate --part` (engine/). A record is the triangle's positions (kPositionBytes: nine
// floats), each corner's channels (io::CornerLayout, in the source's types), the triangle's
// (io::FaceLayout) and, when the channels have them, the three vertex ids (uint64 each). Native
// byte order: records are read back by the build that wrote them.
#pragma once

#include "io/chunk.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace meshstream::io {

class TriangleRecords {
public:
    // The bytes of a triangle's positions: three corners of three floats.
    static constexpr size_t kPositionBytes = 9 * sizeof(float);

    explicit TriangleRecords(const Channels& channels);
    // Bytes per triangle.
    size_t bytes() const { return bytes_; }
    // The record of triangle i of `chunk` (which has at least the channels) into dst[bytes()].
    void encode(const TriangleChunk& chunk, size_t i, std::byte* dst) const;
    // Appends the triangle of the record at src to `chunk` (which has the channels).
    void decode(const std::byte* src, TriangleChunk& chunk) const;
    // Appends the records of every triangle of `chunk` to `out`.
    void encode(const TriangleChunk& chunk, std::vector<char>& out) const;
    // Fills `chunk` (cleared first; capacity at least `triangles`) with `triangles` records from
    // `src`.
    void decode(const char* src, size_t triangles, TriangleChunk& chunk) const;

private:
    CornerLayout corner_;
    FaceLayout face_;
    bool vertex_ids_;
    size_t bytes_;
};

}  // namespace meshstream::io
