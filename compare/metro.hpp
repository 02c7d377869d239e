// Metro-style surface error between two triangle meshes (Cignoni, Rocchini & Scopigno 1998,
// "Metro: measuring error on simplified surfaces"): area-weighted random samples on each
// surface, the distance from every sample to the other surface, and from those the one-sided
// and symmetric Hausdorff distance, mean and RMS. Also counts edges after exact welding
// (boundary = used by one triangle, non-manifold = used by three or more).
//
// Memory: only the smaller mesh (by header triangle count, or a PLY's face count, when both are
// known, else B) is held in memory, with a BVH over its triangles and a BVH over its stored
// samples. The other mesh is streamed twice: pass 1 counts it (area, bounds, edges, a
// fixed-size reservoir of surface points) and pass 2 generates its samples per triangle on the
// fly (not stored) and keeps a running minimum distance for each stored sample of the
// in-memory mesh. Edge counting (compare/topology.hpp) sorts within the memory budget and
// spills sorted runs past it. So memory is O(smaller mesh + sample count) plus that budget,
// independent of the streamed mesh's size.
#pragma once

#include "compare/topology.hpp"
#include "io/format.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace meshstream::compare {

// A mesh that can be read more than once: each open() starts a fresh pass from the first
// triangle. Throws io::Error.
struct MeshSource {
    std::string name;  // for messages and reports
    std::function<std::unique_ptr<io::Reader>()> open;
    bool once = false;  // readable once only (stdin, a pipe): it must be the held mesh
};

// A file ("-" = stdin, or a pipe, which can only be the in-memory side), format `from` (empty:
// detect).
MeshSource file_source(const std::string& path, std::string_view from = {}, const io::ReadOptions& options = {});
// Triangles held by the caller (9 floats each), for tests and in-process comparisons.
MeshSource memory_source(std::string name, std::vector<float> xyz);

struct CompareOptions {
    // Samples per direction; nullopt: default_sample_count(triangles of the sampled mesh).
    std::optional<uint64_t> samples;
    uint64_t seed = 1;
    uint64_t memory_budget_bytes = uint64_t{256} << 20;  // edge counting spills past this
    std::string tmpdir;                                  // for edge spills (empty: $TMPDIR or /tmp)
    // Progress callback (may be empty): phase label, triangles done, total when known.
    std::function<void(std::string_view phase, uint64_t done, std::optional<uint64_t> total)> progress;
};

// clamp(10 · triangles, 1 000 000, 10 000 000).
uint64_t default_sample_count(uint64_t triangle_count);

struct MeshSummary {
    std::string name;
    uint64_t triangles = 0;
    uint64_t non_finite_triangles = 0;  // skipped: a NaN or infinite coordinate
    double area = 0;
    io::Bounds bounds;
    EdgeCounts edges;
    bool in_memory = false;
    double diagonal() const;
};

// Distances from samples on one mesh to the surface of the other.
struct DistanceStats {
    uint64_t samples = 0;
    double max = 0, mean = 0, rms = 0;
};

struct CompareResult {
    MeshSummary a, b;
    DistanceStats a_to_b, b_to_a;
    double diagonal = 0;  // of A's bounding box: the scale for the % figures
    // Symmetric figures, as Metro reports them: the larger of the two directions.
    double hausdorff() const { return std::max(a_to_b.max, b_to_a.max); }
    double mean() const { return std::max(a_to_b.mean, b_to_a.mean); }
    double rms() const { return std::max(a_to_b.rms, b_to_a.rms); }
};

// Compares A and B as described at the top of this file. Deterministic for a given seed and
// inputs. Throws io::Error when a mesh cannot be read, is empty, or changes between passes.
CompareResult compare_meshes(const MeshSource& a, const MeshSource& b, const CompareOptions& options = {});

}  // namespace meshstream::compare
