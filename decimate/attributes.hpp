// Attribute-aware decimation: the per-corner channels of a stream (normals, colours, texture
// coordinates, extra vertex scalars) as one vector of m numbers per corner, and the attribute
// quadric of Hoppe ("New quadric metric for simplifying meshes with appearance attributes", 1999)
// in the memory-efficient form meshoptimizer's simplifier uses: per vertex, for every triangle
// round it, the squared difference between a value and the triangle's linear interpolation of its
// corners' values, area-weighted. The value that minimizes it at a position is the area-weighted
// mean of the interpolations there, so the error minimized over the values is itself a quadric
// in the position (AttributeQuadric::reduced), added to the geometric one to place a merged
// vertex and to rate its collapse.
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

#include "decimate/quadric.hpp"
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

// How a stream's channels map to the m-vector of a corner, and back. Carries normals (3),
// colour (3, or 4 with alpha), each uv set (2) and each vertex scalar (1); per triangle the
// material and the face scalars, which are not part of the vector.
class AttributeLayout {
public:
    AttributeLayout() = default;  // no channel
    // `channels`: the stream's (vertex ids are ignored). Throws std::invalid_argument when a
    // weight names a scalar the stream does not have, or a weight is negative or not finite.
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

// The attribute quadric of m components, kept as size(m) doubles (flat, for a pool):
//   [0, 10)   a Quadric in the position: Σ ω_j A (g_j·x + d_j)² over the triangles,
//   [10]      Σ A (the triangles' areas),
//   [11 + 4j] Σ A g_j (3) and Σ A d_j (1) for component j,
// where g_j·x + d_j interpolates component j over a triangle of area A and ω_j is its weight².
// Positions are relative to the buffer's origin, as the plane quadrics.
struct AttributeQuadric {
    static size_t size(int m) { return 11 + 4 * size_t(m); }
    static void clear(double* q, int m);
    // The quadric of one triangle with corner values a0, a1, a2 (m floats each).
    static void from_triangle(double* q, const double p0[3], const double p1[3], const double p2[3], const float* a0,
                              const float* a1, const float* a2, int m, const double* omega);
    static void add(double* q, const double* r, int m);
    // The error at position x minimized over the values: a quadric in x.
    static Quadric reduced(const double* q, int m, const double* omega);
    // The error at position x with the values fixed at `values`.
    static double error(const double* q, int m, const double* omega, const double x[3], const float* values);
    // The values minimizing the error at x (the area-weighted mean of the interpolations);
    // `fallback` when the quadric has no area.
    static void values(const double* q, int m, const double x[3], const float* fallback, float* out);
    // Σ A: the weight the attribute error carries.
    static double area(const double* q) { return q[10]; }
    // The Quadric in the first 10 numbers (of a quadric, or of one stored in float), and back.
    template <typename T>
    static Quadric part(const T* q) {
        Quadric a;
        a.a00 = q[0], a.a01 = q[1], a.a02 = q[2], a.a11 = q[3], a.a12 = q[4], a.a22 = q[5];
        a.b0 = q[6], a.b1 = q[7], a.b2 = q[8], a.c = q[9];
        return a;
    }
    // Subtracts w·(g·x + d)² from `out`, with g = (g[0], g[1], g[2]) and d = g[3]: what the best
    // value of a component of weight² ω takes off the error, w = ω / ΣA (reduced()).
    static void subtract_square(Quadric& out, double w, const double g[4]) {
        out.a00 -= w * g[0] * g[0];
        out.a01 -= w * g[0] * g[1];
        out.a02 -= w * g[0] * g[2];
        out.a11 -= w * g[1] * g[1];
        out.a12 -= w * g[1] * g[2];
        out.a22 -= w * g[2] * g[2];
        out.b0 -= w * g[0] * g[3];
        out.b1 -= w * g[1] * g[3];
        out.b2 -= w * g[2] * g[3];
        out.c -= w * g[3] * g[3];
    }
    static void set_part(double* q, const Quadric& a) {
        q[0] = a.a00, q[1] = a.a01, q[2] = a.a02, q[3] = a.a11, q[4] = a.a12, q[5] = a.a22;
        q[6] = a.b0, q[7] = a.b1, q[8] = a.b2, q[9] = a.c;
    }
};

}  // namespace meshstream::decimate
