#include "io/read_indexed.hpp"

#include "io/triangle_input.hpp"

#include <utility>

namespace meshstream::io {

IndexedFile read_indexed(const std::string& path, const ReadOptions& options, std::string_view from) {
    // Non-finite triangles are the indexer's to drop or refuse; every other triangle is kept.
    TriangleInput input(open_input(path, from, options), BadTriangles::kKeep);
    IndexedFile out;
    out.format = &input.format();
    const Channels channels = options.channels.of(input.header().channels);
    MeshIndexer indexer(input.name(), "an indexed mesh", channels, options.strict);
    TriangleChunk chunk(TriangleChunk::kDefaultCapacity, channels);
    while (input.next(chunk)) indexer.add(chunk);
    out.header = input.header();
    out.non_finite_triangles = indexer.non_finite_count();
    out.non_finite_attributes = indexer.non_finite_attribute_count();
    out.mesh = indexer.take();
    return out;
}

}  // namespace meshstream::io
