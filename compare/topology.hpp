// Edge and vertex counts of a triangle stream, for `info --topology`, `compare` and the tests:
// vertex, edge, boundary-edge and non-manifold-edge counts. Vertices are the reader's vertex
// ids when the chunks carry them (PLY, OBJ: exact welding by id), otherwise exact positions
// (io::PositionKey: -0.0 == +0.0). An edge is an unordered vertex pair; boundary edges have one
// incident triangle, non-manifold ones three or more. Edges of degenerate triangles that
// repeat a vertex are not counted: met both ways, such an edge would count as two uses and
// make a manifold edge non-manifold.
//
// Memory: io::RecordSorter instances within the given budget, spilling sorted runs to
// temporary files beyond it. Cost: 3 edge records (32 bytes) per triangle, plus for
// TopologyCounter 3 vertex records (16 bytes), i.e. 96 (144) bytes per triangle sorted, in
// memory or on disk, O(n log n) time.
#pragma once

#include "io/chunk.hpp"
#include "io/format.hpp"
#include "io/position_key.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace meshstream::compare {

// A vertex: its position key, or {id, 0} for a reader's vertex id.
using VertexKey = io::PositionKey;

struct EdgeCounts {
    uint64_t edges = 0;               // distinct edges (triangles with a repeated corner add none)
    uint64_t boundary_edges = 0;      // used by exactly one triangle
    uint64_t non_manifold_edges = 0;  // used by three or more triangles
};

class EdgeCounter {
public:
    // `budget_bytes` bounds the sort buffer; runs go to `tmpdir` (empty: $TMPDIR or /tmp).
    explicit EdgeCounter(uint64_t budget_bytes = io::kDefaultMemoryBudget, std::string tmpdir = {});
    ~EdgeCounter();
    EdgeCounter(const EdgeCounter&) = delete;
    EdgeCounter& operator=(const EdgeCounter&) = delete;
    // Adds the three edges of the triangle with these corners.
    void add(const VertexKey (&corners)[3]);
    // The same for a triangle of 9 floats, welded by position.
    void add_triangle(const float* tri);
    // Sorts and counts. Call once. Throws io::Error (temporary files).
    EdgeCounts finish();
    // True when edge records were spilled to temporary files.
    bool spilled() const;

private:
    struct Sorter;
    std::unique_ptr<Sorter> sorter_;
    uint64_t budget_bytes_;
};

struct TopologyReport {
    bool by_vertex_id = false;  // true: vertices are the reader's ids; false: welded positions
    uint64_t vertices = 0;      // distinct vertices used by triangles
    uint64_t edges = 0;
    uint64_t boundary_edges = 0;
    uint64_t non_manifold_edges = 0;
};

class TopologyCounter {
public:
    // `budget_bytes` bounds the sort buffers (a third for vertices, the rest for edges); temp
    // runs go to `tmpdir` (empty: $TMPDIR or /tmp).
    TopologyCounter(uint64_t budget_bytes, std::string tmpdir);
    ~TopologyCounter();
    // Adds a chunk's triangles. The first non-empty chunk decides id or position keys.
    void add(const io::TriangleChunk& chunk);
    // Sorts and counts. Call once. Throws io::Error (temp-file I/O).
    TopologyReport finish();

private:
    struct Vertices;
    std::unique_ptr<Vertices> vertices_;
    EdgeCounter edges_;
    uint64_t budget_bytes_;
    bool decided_ = false;
    bool by_id_ = false;
};

}  // namespace meshstream::compare
