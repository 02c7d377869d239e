// Per-vertex and per-face channels of the in-core mesh, and the seam rules.
#include "decimate/attribute_store.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace meshstream::decimate {

AttributeStore::AttributeStore(const AttributeLayout& layout, size_t triangle_capacity)
    : layout_(layout),
      m_(layout.size()),
      stride_(AttributeQuadric::size(layout.size())),
      face_scalar_count_(layout.face_scalar_count()) {
    if (m_ > kMaxAttributeComponents)
        throw std::invalid_argument(std::to_string(m_) + " attribute values per corner, more than the " +
                                    std::to_string(kMaxAttributeComponents) + " the decimator carries");
    const size_t vertices = 3 * triangle_capacity + 3;
    quadrics_ = raw_array<double>(vertices * stride_);
    values_ = raw_array<float>(std::max<size_t>(1, 3 * vertices * size_t(m_)));
    generation_ = raw_array<uint32_t>(vertices);
    std::fill_n(generation_.get(), vertices, 0u);  // vertex generations start at 1
    vertex_material_ = raw_array<uint32_t>(vertices);
    corners_ = raw_array<float>(std::max<size_t>(1, 3 * triangle_capacity * size_t(m_)));
    if (layout.channels().material) materials_ = raw_array<uint32_t>(triangle_capacity);
    face_scalars_ = raw_array<double>(std::max<size_t>(1, triangle_capacity * face_scalar_count_));
}

size_t AttributeStore::reserved_bytes(const AttributeLayout& layout, size_t triangle_capacity) {
    const size_t m = size_t(layout.size()), vertices = 3 * triangle_capacity + 3;
    return vertices * (8 * AttributeQuadric::size(layout.size()) + 12 * m + 8) +
           triangle_capacity * (12 * m + (layout.channels().material ? 4 : 0) + 8 * layout.face_scalar_count());
}

void AttributeStore::sanitize(float* values, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(values[i])) {
            values[i] = 0;
            ++non_finite_;
        }
}

void AttributeStore::init_vertex(HalfEdgeBuffer& buffer, uint32_t v, const float* value, uint32_t material) {
    generation_[v] = buffer.vertex(v).generation;
    std::copy_n(value, m_, vertex_value(v));
    std::copy_n(value, m_, range_lo(v));
    std::copy_n(value, m_, range_hi(v));
    vertex_material_[v] = material;
    AttributeQuadric::clear(quadric(v), m_);
}

void AttributeStore::ensure_vertex(HalfEdgeBuffer& buffer, uint32_t v, const float* value, uint32_t material) {
    if (generation_[v] != buffer.vertex(v).generation) init_vertex(buffer, v, value, material);
}

void AttributeStore::add_face(HalfEdgeBuffer& buffer, uint32_t f, const float* corners, uint32_t material,
                              const double* face_scalars) {
    const size_t m = size_t(m_);
    std::copy_n(corners, 3 * m, &corners_[3 * size_t(f) * m]);
    if (materials_.get()) materials_[f] = material;
    std::copy_n(face_scalars, face_scalar_count_, &face_scalars_[f * face_scalar_count_]);
    uint32_t v[3];
    double p[3][3];
    for (uint32_t k = 0; k < 3; ++k) {
        v[k] = buffer.corner_vertex(half_edge(f, k));
        buffer.position(v[k], p[k]);
        const float* value = corners + k * m;
        if (generation_[v[k]] != buffer.vertex(v[k]).generation) {
            init_vertex(buffer, v[k], value, material);
        } else if ((buffer.vertex(v[k]).flags & kSeam) == 0 &&
                   (vertex_material_[v[k]] != material || std::memcmp(vertex_value(v[k]), value, 4 * m) != 0)) {
            buffer.vertex(v[k]).flags |= kSeam;
            ++seam_vertices_;
        }
    }
    if (m == 0) return;
    double q[AttributeQuadric::size(kMaxAttributeComponents)];
    AttributeQuadric::from_triangle(q, p[0], p[1], p[2], corners, corners + m, corners + 2 * m, m_, omega());
    for (uint32_t k = 0; k < 3; ++k) AttributeQuadric::add(quadric(v[k]), q, m_);
}

bool AttributeStore::seam_allows(const HalfEdgeBuffer& buffer, uint32_t h) const {
    const uint32_t q_corner = next_in_face(h);
    const uint32_t q = buffer.corner_vertex(q_corner);
    if ((buffer.vertex(q).flags & kSeam) == 0) return true;
    const uint32_t t = buffer.twin(h);
    if (!is_half_edge(t)) return true;  // one face on the edge: one side
    // t runs q→p: its corner is q's on the other face.
    return material(face_of(h)) == material(face_of(t)) &&
           std::memcmp(corner_value(q_corner), corner_value(t), 4 * size_t(m_)) == 0;
}

void AttributeStore::merge(HalfEdgeBuffer& buffer, uint32_t h) {
    const uint32_t p = buffer.corner_vertex(h), q_corner = next_in_face(h), q = buffer.corner_vertex(q_corner);
    if (buffer.vertex(q).flags & kSeam) {
        // p's corners join q on h's side of the seam: they show q's value there.
        const float* wedge = corner_value(q_corner);
        for (uint32_t c = buffer.vertex(p).first_corner; c != kNoIndex; c = buffer.next_corner(c))
            std::copy_n(wedge, m_, corner_value(c));
    }
    AttributeQuadric::add(quadric(q), quadric(p), m_);
    float* lo = range_lo(q);
    float* hi = range_hi(q);
    for (int j = 0; j < m_; ++j) lo[j] = std::min(lo[j], range_lo(p)[j]), hi[j] = std::max(hi[j], range_hi(p)[j]);
}

void AttributeStore::settle(HalfEdgeBuffer& buffer, uint32_t v) {
    const Vertex& x = buffer.vertex(v);
    if ((x.flags & (kSeam | kHasPartner)) != kHasPartner || m_ == 0) return;
    double at[3];
    buffer.position(v, at);
    float out[kMaxAttributeComponents];
    AttributeQuadric::values(quadric(v), m_, at, vertex_value(v), out);
    // The interpolations' mean extrapolates gradients to where the vertex moved, and overshoots
    // next to a sharp change (a halo of colours the mesh never had): each value stays within the
    // range of the input values the vertex stands for.
    const float* lo = range_lo(v);
    const float* hi = range_hi(v);
    for (int j = 0; j < m_; ++j) vertex_value(v)[j] = std::clamp(out[j], lo[j], hi[j]);
}

Quadric AttributeStore::combined(const Quadric& g, const double* a) const {
    const double w = g.a00 + g.a11 + g.a22;
    const Quadric r = AttributeQuadric::reduced(a, m_, omega());
    Quadric out = g;
    out.a00 += w * r.a00;
    out.a01 += w * r.a01;
    out.a02 += w * r.a02;
    out.a11 += w * r.a11;
    out.a12 += w * r.a12;
    out.a22 += w * r.a22;
    out.b0 += w * r.b0;
    out.b1 += w * r.b1;
    out.b2 += w * r.b2;
    out.c += w * r.c;
    return out;
}

}  // namespace meshstream::decimate
