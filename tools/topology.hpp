// `info --topology`: vertex, edge, boundary-edge and non-manifold-edge counts of a triangle
// stream. Vertices are the reader's vertex ids when the chunks carry them (PLY, OBJ: exact
// welding by id), otherwise exact positions (-0.0 == +0.0). An edge is an unordered vertex
// pair; boundary edges have one incident triangle, non-manifold ones three or more. Edges of
// degenerate triangles that repeat a vertex are not counted.
//
// Memory: two io::RecordSorter instances sharing the --memory budget, spilling runs to temp
// files beyond it. Cost: 3 vertex records (16 bytes) and 3 edge records (32 bytes) per
// triangle, i.e. 144 bytes per triangle sorted (in memory or on disk), O(n log n) time.
#pragma once

#include "io/chunk.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace meshstream::tools {

struct TopologyReport {
    bool by_vertex_id = false;  // true: vertices are the reader's ids; false: welded positions
    uint64_t vertices = 0;      // distinct vertices used by triangles
    uint64_t edges = 0;
    uint64_t boundary_edges = 0;
    uint64_t non_manifold_edges = 0;
};

class TopologyCounter {
public:
    // `budget_bytes` bounds the sort buffers; temp runs go to `tmpdir` (empty: $TMPDIR or /tmp).
    TopologyCounter(uint64_t budget_bytes, std::string tmpdir);
    ~TopologyCounter();
    // Adds a chunk's triangles. The first non-empty chunk decides id or position keys.
    void add(const io::TriangleChunk& chunk);
    // Sorts and counts. Call once. Throws io::Error (temp-file I/O).
    TopologyReport finish();

private:
    struct Sorters;
    std::unique_ptr<Sorters> sorters_;
    uint64_t budget_bytes_;
    std::string tmpdir_;
    bool decided_ = false;
    bool by_id_ = false;
};

}  // namespace meshstream::tools
