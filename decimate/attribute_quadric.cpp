// The attribute quadric (Hoppe 1999; meshoptimizer 1.2's quadricFromAttributes /
// quadricReduceAttributes).
#include "decimate/attribute_quadric.hpp"

#include <algorithm>
#include <cmath>

namespace meshstream::decimate {

void AttributeQuadric::clear(double* q, int m) { std::fill_n(q, size(m), 0.0); }

void AttributeQuadric::from_triangle(double* q, const double p0[3], const double p1[3], const double p2[3],
                                     const float* a0, const float* a1, const float* a2, int m, const double* omega) {
    clear(q, m);
    // Barycentric gradients (as meshoptimizer's quadricFromAttributes): with e1 = p1 − p0 and
    // e2 = p2 − p0, a value interpolated over the triangle changes along the plane by
    // g = t1·(a1 − a0) + t2·(a2 − a0).
    const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double area = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(area > 0)) return;  // no area, no weight
    const double d11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    const double d12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    const double d22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    const double denom = d11 * d22 - d12 * d12;
    if (!(denom > 0)) return;
    double t1[3], t2[3];
    for (int i = 0; i < 3; ++i) {
        t1[i] = (d22 * e1[i] - d12 * e2[i]) / denom;
        t2[i] = (d11 * e2[i] - d12 * e1[i]) / denom;
    }
    Quadric a;
    for (int j = 0; j < m; ++j) {
        const double v0 = a0[j], v1 = double(a1[j]) - v0, v2 = double(a2[j]) - v0;
        const double g[3] = {t1[0] * v1 + t2[0] * v2, t1[1] * v1 + t2[1] * v2, t1[2] * v1 + t2[2] * v2};
        const double d = v0 - (g[0] * p0[0] + g[1] * p0[1] + g[2] * p0[2]);
        const double w = omega[j] * area;
        a.a00 += w * g[0] * g[0];
        a.a01 += w * g[0] * g[1];
        a.a02 += w * g[0] * g[2];
        a.a11 += w * g[1] * g[1];
        a.a12 += w * g[1] * g[2];
        a.a22 += w * g[2] * g[2];
        a.b0 += w * g[0] * d;
        a.b1 += w * g[1] * d;
        a.b2 += w * g[2] * d;
        a.c += w * d * d;
        double* gj = q + 11 + 4 * j;
        gj[0] = area * g[0];
        gj[1] = area * g[1];
        gj[2] = area * g[2];
        gj[3] = area * d;
    }
    AttributeQuadric::set_part(q, a);
    q[10] = area;
}

void AttributeQuadric::add(double* q, const double* r, int m) {
    const size_t n = size(m);
    for (size_t i = 0; i < n; ++i) q[i] += r[i];
}

Quadric AttributeQuadric::reduced(const double* q, int m, const double* omega) {
    Quadric out = AttributeQuadric::part(q);
    const double area = q[10];
    if (!(area > 0)) return out;
    // Minimized over value s_j: Σ A (g·x + d − s)² = (that at s = 0) − (G·x + D)² / ΣA.
    for (int j = 0; j < m; ++j) {
        if (omega[j] == 0) continue;
        subtract_square(out, omega[j] / area, q + 11 + 4 * j);
    }
    return out;
}

double AttributeQuadric::error(const double* q, int m, const double* omega, const double x[3], const float* values) {
    Quadric a = AttributeQuadric::part(q);
    double e = a.error(x);
    const double area = q[10];
    for (int j = 0; j < m; ++j) {
        if (omega[j] == 0) continue;
        const double* g = q + 11 + 4 * j;
        const double s = values[j];
        e += omega[j] * s * (area * s - 2 * (g[0] * x[0] + g[1] * x[1] + g[2] * x[2] + g[3]));
    }
    return std::max(e, 0.0);
}

void AttributeQuadric::values(const double* q, int m, const double x[3], const float* fallback, float* out) {
    const double area = q[10];
    for (int j = 0; j < m; ++j) {
        const double* g = q + 11 + 4 * j;
        out[j] = area > 0 ? float((g[0] * x[0] + g[1] * x[1] + g[2] * x[2] + g[3]) / area) : fallback[j];
    }
}

}  // namespace meshstream::decimate
