// Triangles as fixed-size records: see triangle_records.hpp.
#include "io/triangle_records.hpp"

#include <cstring>

namespace meshstream::io {

TriangleRecords::TriangleRecords(const Channels& channels)
    : corner_(channels),
      face_(channels),
      vertex_ids_(channels.vertex_id),
      bytes_(kPositionBytes + 3 * corner_.bytes() + face_.bytes() + (vertex_ids_ ? 3 * sizeof(uint64_t) : 0)) {}

void TriangleRecords::encode(const TriangleChunk& chunk, size_t i, std::byte* dst) const {
    std::memcpy(dst, &chunk.xyz()[9 * i], kPositionBytes);
    dst += kPositionBytes;
    if (const size_t n = corner_.bytes())
        for (int k = 0; k < 3; ++k, dst += n) corner_.pack(chunk, i, k, dst);
    face_.pack(chunk, i, dst);
    dst += face_.bytes();
    if (vertex_ids_) std::memcpy(dst, &chunk.vertex_ids()[3 * i], 3 * sizeof(uint64_t));
}

void TriangleRecords::decode(const std::byte* src, TriangleChunk& chunk) const {
    std::memcpy(chunk.push_slot(), src, kPositionBytes);
    const size_t i = chunk.size() - 1;
    src += kPositionBytes;
    if (const size_t n = corner_.bytes())
        for (int k = 0; k < 3; ++k, src += n) corner_.unpack(src, chunk, i, k);
    face_.unpack(src, chunk, i);
    src += face_.bytes();
    if (vertex_ids_) std::memcpy(chunk.id_at(i), src, 3 * sizeof(uint64_t));
}

void TriangleRecords::encode(const TriangleChunk& chunk, std::vector<char>& out) const {
    const size_t at = out.size(), n = chunk.size();
    out.resize(at + n * bytes_);
    auto* dst = reinterpret_cast<std::byte*>(out.data() + at);
    for (size_t i = 0; i < n; ++i, dst += bytes_) encode(chunk, i, dst);
}

void TriangleRecords::decode(const char* src, size_t triangles, TriangleChunk& chunk) const {
    chunk.clear();
    const auto* from = reinterpret_cast<const std::byte*>(src);
    for (size_t i = 0; i < triangles; ++i, from += bytes_) decode(from, chunk);
}

}  // namespace meshstream::io
