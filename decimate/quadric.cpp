// Garland–Heckbert plane quadrics: construction and the 3×3 minimum solve (Wu & Kobbelt
// 2003, §4.4: vertices move to "the optimal position indicated by the associated error
// quadric" when they are written).
#include "decimate/quadric.hpp"

#include <cmath>

namespace meshstream::decimate {

Quadric Quadric::from_triangle(const double p0[3], const double p1[3], const double p2[3]) {
    const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    Quadric q;
    if (!(len > 0)) return q;
    const double area = 0.5 * len;
    n[0] /= len; n[1] /= len; n[2] /= len;
    const double d = -(n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2]);
    q.a00 = area * n[0] * n[0]; q.a01 = area * n[0] * n[1]; q.a02 = area * n[0] * n[2];
    q.a11 = area * n[1] * n[1]; q.a12 = area * n[1] * n[2]; q.a22 = area * n[2] * n[2];
    q.b0 = area * n[0] * d; q.b1 = area * n[1] * d; q.b2 = area * n[2] * d;
    q.c = area * d * d;
    return q;
}

Quadric Quadric::from_boundary_edge(const double p0[3], const double p1[3], const double p2[3]) {
    const double e[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double f[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const double face[3] = {e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2], e[0] * f[1] - e[1] * f[0]};
    double n[3] = {e[1] * face[2] - e[2] * face[1], e[2] * face[0] - e[0] * face[2],
                   e[0] * face[1] - e[1] * face[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    Quadric q;
    if (!(len > 0)) return q;
    const double w = kBoundaryWeight * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    n[0] /= len; n[1] /= len; n[2] /= len;
    const double d = -(n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2]);
    q.a00 = w * n[0] * n[0]; q.a01 = w * n[0] * n[1]; q.a02 = w * n[0] * n[2];
    q.a11 = w * n[1] * n[1]; q.a12 = w * n[1] * n[2]; q.a22 = w * n[2] * n[2];
    q.b0 = w * n[0] * d; q.b1 = w * n[1] * d; q.b2 = w * n[2] * d;
    q.c = w * d * d;
    return q;
}

bool Quadric::minimum(double x[3]) const {
    // Cofactors of the symmetric matrix A.
    const double c00 = a11 * a22 - a12 * a12;
    const double c01 = a02 * a12 - a01 * a22;
    const double c02 = a01 * a12 - a02 * a11;
    const double det = a00 * c00 + a01 * c01 + a02 * c02;
    // A is a sum of area-weighted n·nᵀ, so its trace is the total area and its eigenvalues
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
    x[0] = r0; x[1] = r1; x[2] = r2;
    return true;
}

}  // namespace meshstream::decimate
