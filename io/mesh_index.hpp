// Turns a triangle soup into an indexed mesh in memory, for the whole-mesh writers (Draco and
// glTF). Vertices are the decimator's vertex ids when the chunks carry the vertex_id channel,
// otherwise exact position welding (bit-equal floats, with -0 == +0), through an
// open-addressing hash table of 32-bit vertex indices (linear probing, load <= 1/2).
// Memory class: whole mesh, about 36 bytes per vertex plus 12 per triangle while indexing.
#pragma once

#include "io/chunk.hpp"
#include "io/format.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace meshstream::io {

struct IndexedMesh {
    std::vector<float> positions;   // xyz per vertex
    std::vector<uint32_t> indices;  // 3 per triangle, counter-clockwise as in the soup
    size_t vertex_count() const { return positions.size() / 3; }
    size_t triangle_count() const { return indices.size() / 3; }
    // Per-axis min/max of the positions (all zero for an empty mesh).
    Bounds bounds() const;
    // Area-weighted smooth vertex normals: the sum of the incident faces' unnormalised
    // cross products, normalised. A vertex whose faces all have zero area gets (0, 0, 1).
    // Returns 3 floats per vertex, each of unit length.
    std::vector<float> smooth_normals() const;
};

// For the whole-mesh writers' --memory checks. `need(vertices, triangles)` is a writer's
// estimate of the bytes it holds for a mesh of that size; `why` says why it holds the whole mesh
// ("Draco encodes the whole mesh in memory"). Throws io::Error naming `file`:
// - budget_check_up_front: when even the smallest mesh of `options`' expected (or promised)
//   triangle count, a closed surface with half as many vertices, needs more than the budget;
// - budget_check: when the `triangles` read so far need more (`need` bytes).
void budget_check_up_front(const std::string& file, const WriteOptions& options, const char* why,
                           uint64_t (*need)(uint64_t vertices, uint64_t triangles, const WriteOptions& options));
void budget_check(const std::string& file, const WriteOptions& options, const char* why, uint64_t triangles,
                  uint64_t need);

class MeshIndexer {
public:
    // `file_name` names the output in error messages.
    explicit MeshIndexer(std::string file_name);

    // Adds a chunk's triangles. Triangles whose corners index the same vertex twice (zero area
    // after welding) are dropped and counted in dropped_triangle_count(): Draco's edgebreaker
    // drops them anyway, and glTF viewers gain nothing from them. Throws io::Error for a
    // non-finite coordinate (naming the triangle's index in the stream), when the index count
    // would pass 2^32 - 1 (32-bit glTF/Draco indices), or when the vertex_id channel appears
    // or disappears mid-stream.
    void add(const TriangleChunk& chunk);

    uint64_t input_triangle_count() const { return input_triangles_; }
    uint64_t dropped_triangle_count() const { return dropped_; }
    size_t vertex_count() const { return mesh_.vertex_count(); }
    size_t triangle_count() const { return mesh_.triangle_count(); }
    // Bytes held by the tables now (positions, ids, hash slots, indices), for budget checks.
    uint64_t memory_bytes() const;

    // Releases the mesh; the indexer is empty afterwards.
    IndexedMesh take();

private:
    uint32_t vertex_for_position(const float* p);
    uint32_t vertex_for_id(uint64_t id, const float* p);
    void grow();

    std::string file_name_;
    IndexedMesh mesh_;
    std::vector<uint64_t> ids_;      // per vertex, in id mode
    std::vector<uint32_t> slots_;    // hash table of vertex indices; kEmpty = free
    int id_mode_ = -1;               // -1 undecided, 0 positions, 1 vertex ids
    uint64_t input_triangles_ = 0;
    uint64_t dropped_ = 0;
};

}  // namespace meshstream::io
