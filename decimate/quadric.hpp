// Garland–Heckbert plane quadrics (Garland & Heckbert 1997), as used by Wu & Kobbelt 2003,
// §4.2 (each incoming triangle adds its weighted squared plane equation to its three
// vertices; weighted by the square root of its area, as meshoptimizer's simplifier does), §4.3 (a half-edge collapse
// p→q is rated by (Q_p + Q_q)(q)) and §4.4 (a written vertex moves once to the minimum of its quadric). Coordinates are
// relative to an origin chosen by the caller so that large scan coordinates do not cancel catastrophically.
#pragma once

#include <cmath>

namespace meshstream::decimate {

// Q(x) = xᵀAx + 2bᵀx + c with A symmetric (a00 a01 a02 / a11 a12 / a22).
struct Quadric {
    double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
    double b0 = 0, b1 = 0, b2 = 0;
    double c = 0;

    // The plane of triangle (p0, p1, p2) weighted by the square root of its area (a length).
    // A degenerate triangle (zero area) gives the zero quadric.
    static Quadric from_triangle(const double p0[3], const double p1[3], const double p2[3]);

    // Garland & Heckbert's boundary constraint for the open edge (p0, p1) of triangle
    // (p0, p1, p2): the plane through the edge perpendicular to the triangle, weighted by
    // kBoundaryWeight · |p1 − p0| (a length, like the face quadrics' weights). Zero when
    // degenerate.
    static Quadric from_boundary_edge(const double p0[3], const double p1[3], const double p2[3]);
    static constexpr double kBoundaryWeight = 1.0;

    Quadric& operator+=(const Quadric& o) {
        a00 += o.a00;
        a01 += o.a01;
        a02 += o.a02;
        a11 += o.a11;
        a12 += o.a12;
        a22 += o.a22;
        b0 += o.b0;
        b1 += o.b1;
        b2 += o.b2;
        c += o.c;
        return *this;
    }
    friend Quadric operator+(Quadric a, const Quadric& b) { return a += b; }

    // The quadric error at x (weight × squared distance summed over the planes; ≥ 0 up to
    // round-off).
    double error(const double x[3]) const {
        const double ax0 = a00 * x[0] + a01 * x[1] + a02 * x[2];
        const double ax1 = a01 * x[0] + a11 * x[1] + a12 * x[2];
        const double ax2 = a02 * x[0] + a12 * x[1] + a22 * x[2];
        return x[0] * (ax0 + 2 * b0) + x[1] * (ax1 + 2 * b1) + x[2] * (ax2 + 2 * b2) + c;
    }

    // Solves A x = -b (the minimum of Q) by Cramer's rule. Returns false, leaving `x`
    // untouched, when A is singular or too ill-conditioned to trust (flat or cylindrical
    // neighbourhoods), so the caller can fall back to a position of its choosing.
    bool minimum(double x[3]) const {
        // Cofactors of the symmetric matrix A.
        const double c00 = a11 * a22 - a12 * a12;
        const double c01 = a02 * a12 - a01 * a22;
        const double c02 = a01 * a12 - a02 * a11;
        const double det = a00 * c00 + a01 * c01 + a02 * c02;
        // A is a sum of weighted n·nᵀ, so its trace is the total weight and its eigenvalues
        // lie in [0, trace]. Demand the determinant to be a fair fraction of the largest
        // possible one: below that, one direction is nearly unconstrained (a flat or
        // cylindrical patch) and the "optimum" would run off along it.
        const double trace = a00 + a11 + a22;
        if (!(trace > 0) || !(std::fabs(det) > 1e-9 * trace * trace * trace)) return false;
        const double c11 = a00 * a22 - a02 * a02;
        const double c12 = a01 * a02 - a00 * a12;
        const double c22 = a00 * a11 - a01 * a01;
        const double inv = -1.0 / det;
        const double r0 = (c00 * b0 + c01 * b1 + c02 * b2) * inv;
        const double r1 = (c01 * b0 + c11 * b1 + c12 * b2) * inv;
        const double r2 = (c02 * b0 + c12 * b1 + c22 * b2) * inv;
        if (!std::isfinite(r0) || !std::isfinite(r1) || !std::isfinite(r2)) return false;
        x[0] = r0;
        x[1] = r1;
        x[2] = r2;
        return true;
    }

    // The error at the minimum x found by minimum(): there A x = −b, so Q(x) = c + bᵀx (no
    // matrix product).
    double error_at_minimum(const double x[3]) const { return c + b0 * x[0] + b1 * x[1] + b2 * x[2]; }
};

}  // namespace meshstream::decimate
