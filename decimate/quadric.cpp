// Garland–Heckbert plane quadrics: construction and the 3×3 minimum solve (Wu & Kobbelt
// 2003, §4.4: vertices move to "the optimal position indicated by the associated error
// quadric" when they are written).
#include "decimate/quadric.hpp"

#include <cmath>

namespace meshstream::decimate {
namespace {

// w times the quadric of the plane through p0 with normal n (of length len > 0).
Quadric weighted_plane(const double n_in[3], double len, const double p0[3], double w) {
    const double n[3] = {n_in[0] / len, n_in[1] / len, n_in[2] / len};
    const double d = -(n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2]);
    Quadric q;
    q.a00 = w * n[0] * n[0];
    q.a01 = w * n[0] * n[1];
    q.a02 = w * n[0] * n[2];
    q.a11 = w * n[1] * n[1];
    q.a12 = w * n[1] * n[2];
    q.a22 = w * n[2] * n[2];
    q.b0 = w * n[0] * d;
    q.b1 = w * n[1] * d;
    q.b2 = w * n[2] * d;
    q.c = w * d * d;
    return q;
}

}  // namespace

Quadric Quadric::from_triangle(const double p0[3], const double p1[3], const double p2[3]) {
    const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) return Quadric{};
    // The plane weighted by the square root of the area, as meshoptimizer's simplifier does:
    // by the area, small triangles count for too little (a low-poly model's feet and fingers
    // go first), and unweighted, a scan's tiny slivers count for as much as its large faces.
    const double w = std::sqrt(0.5 * len);
    return weighted_plane(n, len, p0, w);
}

Quadric Quadric::from_boundary_edge(const double p0[3], const double p1[3], const double p2[3]) {
    const double e[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double f[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const double face[3] = {e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2], e[0] * f[1] - e[1] * f[0]};
    const double n[3] = {e[1] * face[2] - e[2] * face[1], e[2] * face[0] - e[0] * face[2],
                         e[0] * face[1] - e[1] * face[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) return Quadric{};
    const double w = kBoundaryWeight * std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    return weighted_plane(n, len, p0, w);
}

}  // namespace meshstream::decimate
