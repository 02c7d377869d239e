// The attribute quadric of Hoppe ("New quadric metric for simplifying meshes with appearance
// attributes", 1999) in the memory-efficient form meshoptimizer's simplifier uses: per vertex, for
// every triangle round it, the squared difference between a value and the triangle's linear
// interpolation of its corners' values, area-weighted. The value that minimizes it at a position
// is the area-weighted mean of the interpolations there, so the error minimized over the values is
// itself a quadric in the position (AttributeQuadric::reduced), added to the geometric one to
// place a merged vertex and to rate its collapse (decimate/attributes.hpp: the balance of the two).
#pragma once

#include "decimate/quadric.hpp"

#include <cstddef>

namespace meshstream::decimate {

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
