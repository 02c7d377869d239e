// Garland–Heckbert plane quadrics (Garland & Heckbert 1997), as used by Wu & Kobbelt 2003,
// §4.2 (each incoming triangle adds its area-weighted squared plane equation to its three
// vertices), §4.3 (a half-edge collapse p→q is rated by (Q_p + Q_q)(q)) and §4.4 (a written
// vertex moves once to the minimum of its quadric). Coordinates are relative to an origin
// chosen by the caller so that large scan coordinates do not cancel catastrophically.
#pragma once

namespace meshstream::decimate {

// Q(x) = xᵀAx + 2bᵀx + c with A symmetric (a00 a01 a02 / a11 a12 / a22).
struct Quadric {
    double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
    double b0 = 0, b1 = 0, b2 = 0;
    double c = 0;

    // The plane of triangle (p0, p1, p2) weighted by its area. A degenerate triangle (zero
    // area) gives the zero quadric.
    static Quadric from_triangle(const double p0[3], const double p1[3], const double p2[3]);

    // Garland & Heckbert's boundary constraint for the open edge (p0, p1) of triangle
    // (p0, p1, p2): the plane through the edge perpendicular to the triangle, weighted by
    // kBoundaryWeight · |p1 − p0|² (an area, like the face quadrics). Zero when degenerate.
    static Quadric from_boundary_edge(const double p0[3], const double p1[3], const double p2[3]);
    static constexpr double kBoundaryWeight = 1.0;

    Quadric& operator+=(const Quadric& o) {
        a00 += o.a00; a01 += o.a01; a02 += o.a02; a11 += o.a11; a12 += o.a12; a22 += o.a22;
        b0 += o.b0; b1 += o.b1; b2 += o.b2; c += o.c;
        return *this;
    }
    friend Quadric operator+(Quadric a, const Quadric& b) { return a += b; }

    // The quadric error at x (area × squared distance summed over the planes; ≥ 0 up to
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
    bool minimum(double x[3]) const;
};

}  // namespace meshstream::decimate
