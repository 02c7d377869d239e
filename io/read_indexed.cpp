#include "io/read_indexed.hpp"

#include "io/triangle_input.hpp"

#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

namespace meshstream::io {

namespace {

constexpr const char* kWhat = "an indexed mesh";

// Non-finite values become 0; returns how many there were.
template <class T>
uint64_t zero_non_finite(T* v, size_t n) {
    uint64_t bad = 0;
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(v[i])) v[i] = 0, ++bad;
    return bad;
}

// A file whose reader gives its own vertices and faces (PLY): the vertices are read in file
// order, the triangles kept as indices into them, then the vertices no kept triangle uses are
// dropped (file order kept). What MeshIndexer would weld is already one vertex: a PLY corner is
// its vertex, attributes and all.
void read_own_indices(const std::string& name, IndexedSource& source, const Channels& channels, bool strict,
                      IndexedFile& out) {
    IndexedMesh& mesh = out.mesh;
    mesh.channels = channels;
    mesh.channels.vertex_id = false;
    mesh.channels.face_scalars.clear();
    const CornerLayout layout(mesh.channels);
    const size_t rb = layout.bytes();
    const uint64_t n = source.vertex_count();
    mesh.positions.resize(3 * n);
    mesh.attributes.resize(rb * n);
    // Per vertex: 1 when its coordinates are finite, then 2 added when a kept triangle uses it.
    std::vector<uint8_t> state(n);
    for (uint64_t v = 0; v < n; ++v) {
        float* p = &mesh.positions[3 * v];
        source.vertex(v, p, rb ? &mesh.attributes[rb * v] : nullptr);
        state[v] = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) ? 1 : 0;
    }
    constexpr size_t kBatch = size_t{1} << 16;  // triangles
    std::vector<uint32_t> batch;
    uint64_t read = 0;  // triangles read, the dropped ones too
    while (batch.clear(), source.next_triangles(batch, kBatch)) {
        for (size_t t = 0; t < batch.size(); t += 3, ++read) {
            const uint32_t* c = &batch[t];
            if (!(state[c[0]] & state[c[1]] & state[c[2]] & 1)) {
                if (strict) throw non_finite_triangle_error(name, kWhat, read);
                ++out.non_finite_triangles;
                continue;
            }
            if (mesh.indices.size() + 3 > 0xFFFFFFFFull) throw index_count_error(name, kWhat, read + 1);
            mesh.indices.insert(mesh.indices.end(), c, c + 3);
            state[c[0]] |= 2, state[c[1]] |= 2, state[c[2]] |= 2;
        }
    }
    // The used vertices, moved down in file order, and the indices renumbered, when some are not.
    uint64_t kept = 0;
    for (const uint8_t v : state) kept += (v & 2) != 0;
    if (kept < n) {
        std::vector<uint32_t> renumber(n);
        uint64_t k = 0;
        for (uint64_t v = 0; v < n; ++v) {
            if (!(state[v] & 2)) continue;
            renumber[v] = static_cast<uint32_t>(k);
            std::memmove(&mesh.positions[3 * k], &mesh.positions[3 * v], 3 * sizeof(float));
            if (rb) std::memmove(&mesh.attributes[rb * k], &mesh.attributes[rb * v], rb);
            ++k;
        }
        for (uint32_t& i : mesh.indices) i = renumber[i];
        mesh.positions.resize(3 * kept);
        mesh.attributes.resize(rb * kept);
        mesh.positions.shrink_to_fit();
        mesh.attributes.shrink_to_fit();
    }
    // Non-finite attribute values are stored as 0 (glTF and Draco hold none), counted per vertex.
    if (rb) {
        float normal[3], rgba[4], uv[2 * kMaxUvSets];
        std::vector<double> scalars(mesh.channels.vertex_scalars.size());
        const size_t uv_values = 2 * size_t(mesh.channels.uv_sets);
        for (uint64_t v = 0; v < kept; ++v) {
            std::byte* record = &mesh.attributes[rb * v];
            layout.unpack_values(record, normal, rgba, uv, scalars.data());
            const uint64_t bad = (mesh.channels.normal ? zero_non_finite(normal, 3) : 0) +
                                 (mesh.channels.color ? zero_non_finite(rgba, 4) : 0) +
                                 zero_non_finite(uv, uv_values) + zero_non_finite(scalars.data(), scalars.size());
            if (bad == 0) continue;
            out.non_finite_attributes += bad;
            layout.pack_values(normal, rgba, uv, scalars.data(), record);
        }
    }
}

}  // namespace

IndexedFile read_indexed(const std::string& path, const ReadOptions& options, std::string_view from) {
    // Non-finite triangles are the indexer's to drop or refuse; every other triangle is kept.
    TriangleInput input(open_input(path, from, options), BadTriangles::kKeep);
    IndexedFile out;
    out.format = &input.format();
    const Channels channels = options.channels.of(input.header().channels);
    if (IndexedSource* own = channels.material ? nullptr : input.reader().indexed()) {
        read_own_indices(input.name(), *own, channels, options.strict, out);
        out.header = input.header();
        return out;
    }
    MeshIndexer indexer(input.name(), kWhat, channels, options.strict);
    TriangleChunk chunk(TriangleChunk::kDefaultCapacity, channels);
    while (input.next(chunk)) indexer.add(chunk);
    out.header = input.header();
    out.non_finite_triangles = indexer.non_finite_count();
    out.non_finite_attributes = indexer.non_finite_attribute_count();
    out.mesh = indexer.take();
    return out;
}

}  // namespace meshstream::io
