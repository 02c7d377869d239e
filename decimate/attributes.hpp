// Attribute-aware decimation: the per-corner channels of a stream (normals, colours, texture
// coordinates, extra vertex scalars) as one vector of m numbers per corner (AttributeLayout), and
// the weights of their error (AttributeWeights). With channels the decimator rates a collapse by
// its geometric error plus the attribute error of Hoppe ("New quadric metric for simplifying
// meshes with appearance attributes", 1999), kept as meshoptimizer's simplifier keeps it
// (decimate/attribute_quadric.hpp).
//
// Balance with geometry: the plane quadrics weigh a triangle by the square root of its area, so
// the geometric error over a neighbourhood of total weight W is W times a mean squared distance;
// the attribute error is the area times the squared value difference. With channels a collapse
// is rated, as meshoptimizer 1.2 rates it, by geometric error / W + attribute error: the same
// balance between distance and value difference at every scale (a value step of 1 over a
// distance d weighs as a move of d). A channel's weight multiplies its values (error ∝ weight²),
// as meshoptimizer's attribute weights do. Positions-only streams keep the geometric error as it
// is (not divided by W).
//
// Seams: a vertex whose corners disagree (a UV or normal seam, a colour border stored per corner)
// or whose triangles have different materials is a seam vertex (kSeam): it never moves, so no
// texture stretches across a seam; a collapse into it gives the removed vertex's corners the
// value its corner has on that side (refused where the two triangles on the edge disagree there,
// the seam running along the edge); and it is removed only by sliding along its seam into a seam
// neighbour, each side taking that neighbour's value there (AttributeStore::slides).
#pragma once

#include "io/chunk.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace meshstream::decimate {

// Per-channel weights (multipliers of the values; 0 leaves a channel out of the error, but it is
// still interpolated).
struct AttributeWeights {
    // Normals weigh half: at 1 their error pulls the geometry off more than meshoptimizer's does
    // at the same normal error (docs/decimation.md, measured).
    double normal = 0.5;
    double color = 1;  // RGB(A) in 0..1
    double uv = 1;
    // Named vertex scalars (intensity, confidence): interpolated, weighted only when named here.
    std::vector<std::pair<std::string, double>> scalars;
};

// The most components a corner's vector may have (AttributeLayout::size()): a decimator given a
// larger layout throws std::invalid_argument.
inline constexpr int kMaxAttributeComponents = 32;

// How a stream's channels map to the m-vector of a corner, and back. Carries normals (3),
// colour (3, or 4 with alpha), each uv set (2) and each vertex scalar (1); per triangle the
// material and the face scalars, which are not part of the vector.
class AttributeLayout {
public:
    AttributeLayout() = default;  // no channel
    // `channels`: the stream's (vertex ids are ignored). Throws io::OptionError (Setting::kWeights)
    // when a weight names a scalar the stream does not have, or a weight is negative or not finite.
    AttributeLayout(const io::Channels& channels, const AttributeWeights& weights);

    int size() const { return size_; }  // m
    // True when the decimator carries anything besides positions.
    bool any() const { return size_ > 0 || channels_.material || !channels_.face_scalars.empty(); }
    // The channels the decimator's output carries (with vertex ids).
    const io::Channels& channels() const { return channels_; }
    // Weight² of each of the m components (what the quadrics use).
    const std::vector<double>& omega() const { return omega_; }
    // True when some component has a non-zero weight (else values are only interpolated).
    bool weighted() const { return weighted_; }
    size_t face_scalar_count() const { return channels_.face_scalars.size(); }

    // True when chunks with `channels` hold every channel this layout reads (in the same order).
    bool carried_by(const io::Channels& channels) const;
    // Corner `corner` of triangle `i` of `chunk` (which has at least these channels) into m floats.
    void gather(const io::TriangleChunk& chunk, size_t i, int corner, float* out) const;
    // m floats into corner `corner` of triangle `i` of `chunk` (which has channels()): normals
    // normalized (a zero one stays zero), colours clamped to 0..1.
    void scatter(const float* in, io::TriangleChunk& chunk, size_t i, int corner) const;

private:
    io::Channels channels_;
    int size_ = 0;
    int normal_ = -1, color_ = -1, color_size_ = 0, uv_ = -1, scalar_ = -1;
    std::vector<double> omega_;
    bool weighted_ = false;
};

}  // namespace meshstream::decimate
