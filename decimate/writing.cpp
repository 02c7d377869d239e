// Multiple-choice writing and write-time vertex placement (Wu & Kobbelt 2003, §4.4).
#include "decimate/writing.hpp"

#include "decimate/attribute_store.hpp"
#include "decimate/collapse.hpp"

#include <algorithm>

namespace meshstream::decimate {

TriangleOutput::TriangleOutput(size_t chunk_triangles, const AttributeLayout* layout)
    : chunk_(chunk_triangles, layout ? layout->channels() : io::Channels::ids_only()), layout_(layout) {}

void TriangleOutput::emit(const float xyz[9], const uint64_t ids[3], const Emit& out, const float* const corners[3],
                          uint32_t material, const double* face_scalars) {
    const size_t i = chunk_.size();
    float* slot = chunk_.push_slot();
    std::copy(xyz, xyz + 9, slot);
    std::copy(ids, ids + 3, chunk_.id_at(i));
    for (int k = 0; k < 3; ++k) layout_->scatter(corners[k], chunk_, i, k);
    if (uint32_t* m = chunk_.material_at(i)) *m = material;
    for (size_t c = 0; c < layout_->face_scalar_count(); ++c) *chunk_.face_scalar_at(i, c) = face_scalars[c];
    ++triangle_count_;
    if (chunk_.full()) flush(out);
}

void TriangleOutput::emit(const float xyz[9], const uint64_t ids[3], const Emit& out) {
    float* slot = chunk_.push_slot();
    std::copy(xyz, xyz + 9, slot);
    uint64_t* id = chunk_.id_at(chunk_.size() - 1);
    id[0] = ids[0];
    id[1] = ids[1];
    id[2] = ids[2];
    ++triangle_count_;
    if (chunk_.full()) flush(out);
}

void TriangleOutput::flush(const Emit& out) {
    if (chunk_.empty()) return;
    out(chunk_);
    chunk_.clear();
}

uint32_t pick_write(HalfEdgeBuffer& buffer) { return buffer.oldest_interior_face(); }

bool place_vertex(HalfEdgeBuffer& buffer, uint32_t v) {
    const Vertex& x = buffer.vertex(v);
    if ((x.flags & (kInHash | kNonManifold | kFrozen | kSeam)) != 0 || x.open_edges != 0) return false;
    // Nothing collapsed into v: every plane of its quadric passes through v, so its own
    // position is the minimum, and a solve would only move it by round-off.
    if ((x.flags & kHasPartner) == 0) return false;
    // With weighted channels, the minimum of geometric and attribute error (attributes.hpp).
    const AttributeStore* attributes = buffer.attributes();
    Quadric q = buffer.quadric(v);
    if (attributes != nullptr && attributes->weighted())
        q = AttributeStore::combined(q, attributes->reduced(buffer, v));
    double old[3], best[3];
    buffer.position(v, old);
    if (!q.minimum(best)) {
        // No unique minimum (flat or cylindrical neighbourhood): as Garland & Heckbert, take
        // the best of the collapsed edge's ends and its midpoint — here the far end p of the
        // last collapse into v (v itself is the other end, the old position).
        double far_end[3];
        if (!buffer.partner_position(v, far_end)) return false;
        double error = q.error(old);
        bool found = false;
        double mid[3] = {0.5 * (old[0] + far_end[0]), 0.5 * (old[1] + far_end[1]), 0.5 * (old[2] + far_end[2])};
        buffer.round_position(mid);
        const double* candidates[2] = {far_end, mid};
        for (const double* candidate : candidates) {
            const double e = q.error(candidate);
            if (e < error) {
                error = e;
                std::copy(candidate, candidate + 3, best);
                found = true;
            }
        }
        if (!found) return false;
    }
    // Judged where the vertex will really be: its float position. Far from the origin a float
    // step is large (0.25 m at 4 000 000, as in UTM coordinates), and the unrounded optimum
    // of a slope moved vertices up to 9 cm off it when stored.
    buffer.round_position(best);
    double reach2 = 0;
    for (uint32_t c = x.first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        double w[3];
        buffer.position(buffer.corner_vertex(next_in_face(c)), w);
        const double d2 =
            (w[0] - old[0]) * (w[0] - old[0]) + (w[1] - old[1]) * (w[1] - old[1]) + (w[2] - old[2]) * (w[2] - old[2]);
        reach2 = std::max(reach2, d2);
    }
    const double move2 = (best[0] - old[0]) * (best[0] - old[0]) + (best[1] - old[1]) * (best[1] - old[1]) +
                         (best[2] - old[2]) * (best[2] - old[2]);
    if (move2 > reach2) return false;
    if (!(q.error(best) <= q.error(old))) return false;
    if (!moves_keep_faces_valid(buffer, v, old, best, kNoIndex, kNoIndex)) return false;
    buffer.set_position(v, best);
    return true;
}

int write_face(HalfEdgeBuffer& buffer, uint32_t f, uint64_t& next_id, TriangleOutput& output, const Emit& out) {
    float xyz[9];
    uint64_t ids[3];
    uint32_t v[3];
    int moved = 0;
    AttributeStore* attributes = buffer.attributes();
    for (int k = 0; k < 3; ++k) {
        v[k] = buffer.corner_vertex(half_edge(f, k));
        if ((buffer.vertex(v[k]).flags & kFrozen) == 0) {
            moved += place_vertex(buffer, v[k]) ? 1 : 0;
            if (attributes) attributes->settle(buffer, v[k]);
            buffer.freeze(v[k], next_id++);
        }
    }
    for (int k = 0; k < 3; ++k) {
        const Vertex& x = buffer.vertex(v[k]);
        xyz[3 * k] = x.pos[0];
        xyz[3 * k + 1] = x.pos[1];
        xyz[3 * k + 2] = x.pos[2];
        ids[k] = x.id;
    }
    if (attributes) {
        const float* corners[3];
        for (uint32_t k = 0; k < 3; ++k) corners[k] = attributes->shown(buffer, half_edge(f, k));
        output.emit(xyz, ids, out, corners, attributes->material(f), attributes->face_scalars(f));
    } else {
        output.emit(xyz, ids, out);
    }
    for (int k = 0; k < 3; ++k) {
        const uint32_t h = half_edge(f, k);
        const uint32_t t = buffer.twin(h);
        if (is_half_edge(t)) {
            buffer.set_twin(t, kWrittenEdge);  // the neighbour now borders P_out
        } else if (t == kOpenEdge && ((buffer.vertex(v[k]).flags | buffer.vertex(v[(k + 1) % 3]).flags) & kInHash)) {
            // A forced write of a face still open towards the input: remember the edge so the
            // partner arriving later closes it against P_out.
            buffer.add_written_stub(v[k], v[(k + 1) % 3]);
        }
    }
    buffer.detach_face(f);
    for (int k = 0; k < 3; ++k) {
        const Vertex& x = buffer.vertex(v[k]);
        if ((x.flags & kAlive) && x.face_count == 0 && (x.flags & kInHash) == 0) buffer.free_vertex(v[k]);
    }
    return moved;
}

void pass_through(HalfEdgeBuffer& buffer, const uint32_t vertex[3], uint64_t& next_id, TriangleOutput& output,
                  const Emit& out, const PassedChannels* channels) {
    float xyz[9];
    uint64_t ids[3];
    AttributeStore* attributes = buffer.attributes();
    for (int k = 0; k < 3; ++k) {
        const Vertex& x = buffer.vertex(vertex[k]);
        if (attributes && channels)
            attributes->ensure_vertex(buffer, vertex[k], channels->corners[k], channels->material);
        if ((x.flags & kFrozen) == 0) buffer.freeze(vertex[k], next_id++);
        xyz[3 * k] = x.pos[0];
        xyz[3 * k + 1] = x.pos[1];
        xyz[3 * k + 2] = x.pos[2];
        ids[k] = x.id;
    }
    if (channels)
        output.emit(xyz, ids, out, channels->corners, channels->material, channels->face_scalars);
    else
        output.emit(xyz, ids, out);
}

}  // namespace meshstream::decimate
