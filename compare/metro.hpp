// Metro-style surface error between two triangle meshes (Cignoni, Rocchini & Scopigno 1998,
// "Metro: measuring error on simplified surfaces"): area-weighted random samples on each
// surface, the distance from every sample to the other surface, and from those the one-sided
// and symmetric Hausdorff distance, mean and RMS. Also counts edges after exact welding
// (boundary = used by one triangle, non-manifold = used by three or more).
//
// With CompareOptions::attributes it also measures colour and normal error at the same
// samples, in the manner of the attribute deviation of Roy, Foufou & Truchetet (2004,
// MeshDev): each sample's value interpolated (barycentric, from its triangle's three corners)
// on its own surface against the value interpolated at its nearest point of the other
// surface. Colour error is the Euclidean distance of RGB in 0..1 (alpha ignored); normal error
// the angle between the two normals, each normalised. Only the channels both meshes carry are
// measured.
//
// Memory: only the smaller mesh (by header triangle count, or a PLY's face count, when both are
// known, else B) is held in memory, with a BVH over its triangles and a BVH over its stored
// samples. The other mesh is streamed twice: pass 1 counts it (area, bounds, edges, a
// fixed-size reservoir of surface points) and pass 2 generates its samples per triangle on the
// fly (not stored) and keeps a running minimum distance for each stored sample of the
// in-memory mesh. Edge counting (compare/topology.hpp) sorts within the memory budget and
// spills sorted runs past it. So memory is O(smaller mesh + sample count) plus that budget,
// independent of the streamed mesh's size. Each measured attribute (colour: RGB, normal: xyz;
// 3 floats) adds 36 bytes per held triangle (its three corners), 24 per held sample (its own
// value and the value at its nearest point of the streamed mesh so far, replaced whenever
// that point is) and 12 per reservoir point (the reservoir is freed before pass 2). The
// streamed mesh's samples take their values from the streamed triangle as they are drawn.
#pragma once

#include "compare/topology.hpp"
#include "io/error.hpp"
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
// Triangles held by the caller (9 floats each), for tests and in-process comparisons, with
// per-corner normals (9 floats a triangle) and colours (12: RGBA 0..1 per corner, the chunk's
// layout) when those vectors are not empty; they must then match xyz's triangle count.
MeshSource memory_source(std::string name, std::vector<float> xyz, std::vector<float> normals = {},
                         std::vector<float> colors = {});

struct CompareOptions {
    // Samples per direction; nullopt: default_sample_count(triangles of the sampled mesh).
    std::optional<uint64_t> samples;
    uint64_t seed = 1;
    uint64_t memory_budget_bytes = io::kDefaultMemoryBudget;  // edge counting spills past this
    std::string tmpdir;                                  // for edge spills (empty: $TMPDIR or /tmp)
    // Also measure colour and normal error (the channels both meshes have; see the top of this
    // file). The sources are read with those channels, so their readers must keep them (a
    // file_source's ReadOptions::channels).
    bool attributes = false;
    // Count both meshes' edges (MeshSummary::edges: boundary and non-manifold edges, which the
    // result's notes use); false leaves them 0, for callers that want the distances only.
    bool edges = true;
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
    io::Channels channels;  // what the mesh carries, as its reader's header states
    double diagonal() const;
};

// Distances from samples on one mesh to the surface of the other.
struct DistanceStats {
    uint64_t samples = 0;
    double max = 0, mean = 0, rms = 0;
};

// The error of one attribute between the samples on one mesh and the values at their nearest
// points of the other: colour as RGB distance (0..sqrt 3), normals as an angle in degrees.
struct AttributeStats {
    uint64_t samples = 0;  // samples measured
    // Samples not measured: an interpolated normal of zero length (opposite corner normals) or
    // a non-finite value, on either side.
    uint64_t skipped = 0;
    double max = 0, rms = 0;
};

// What compare_meshes measures of the attributes with CompareOptions::attributes.
struct AttributeErrors {
    bool color = false, normal = false;  // the channels both meshes have: those measured
    AttributeStats color_a_to_b, color_b_to_a, normal_a_to_b, normal_b_to_a;  // normals in degrees
    // Symmetric figures as for distances: the larger max and RMS of the two directions, the
    // samples (and skipped ones) of both.
    static AttributeStats symmetric(const AttributeStats& x, const AttributeStats& y);
    AttributeStats color_symmetric() const { return symmetric(color_a_to_b, color_b_to_a); }
    AttributeStats normal_symmetric() const { return symmetric(normal_a_to_b, normal_b_to_a); }
};

struct CompareResult {
    MeshSummary a, b;
    DistanceStats a_to_b, b_to_a;
    double diagonal = 0;  // of A's bounding box: the scale for the % figures
    std::optional<AttributeErrors> attributes;  // with CompareOptions::attributes
    // Symmetric figures, as Metro reports them: the larger of the two directions.
    double hausdorff() const { return std::max(a_to_b.max, b_to_a.max); }
    double mean() const { return std::max(a_to_b.mean, b_to_a.mean); }
    double rms() const { return std::max(a_to_b.rms, b_to_a.rms); }
};

// Thrown by compare_meshes with CompareOptions::attributes when the two meshes share neither
// colours nor normals, before any triangle is read; what() names what each one has. An
// io::OptionError about Setting::kAttributes: the setting cannot work with these meshes.
class NoSharedAttributes : public io::OptionError {
public:
    explicit NoSharedAttributes(std::string message) : io::OptionError(io::Setting::kAttributes, std::move(message)) {}
};

// Compares A and B as described at the top of this file. Deterministic for a given seed and
// inputs. Throws io::Error when a mesh cannot be read, is empty, or changes between passes, and
// NoSharedAttributes as said above.
CompareResult compare_meshes(const MeshSource& a, const MeshSource& b, const CompareOptions& options = {});

// The one-sided Hausdorff distance from surface `from` to surface `to`, both held by the caller
// (9 floats a triangle; triangles with a non-finite coordinate are skipped): the largest
// distance from about `samples` samples on `from`, spread by area as compare_meshes spreads them
// (deterministic for a seed), to the nearest point of `to`; 0 when either side is empty. For
// callers that hold both sides (the tiles' errors). Memory: `to` with its BVH.
double one_sided_hausdorff(const std::vector<float>& from, std::vector<float> to, uint64_t samples,
                           uint64_t seed = 1);

}  // namespace meshstream::compare
