// The in-core half-edge buffer: pools, welding hash table, READ (Wu & Kobbelt 2003, §4.2)
// and the bookkeeping of the boundary polygons P_in and P_out (§4).
#include "decimate/halfedge_buffer.hpp"

#include "io/hash.hpp"

#include <bit>
#include <cassert>
#include <cmath>
#include <cstring>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace meshstream::decimate {

void* allocate_pool(size_t bytes) {
    constexpr size_t kHugePage = size_t{2} << 20;
    if (bytes < 2 * kHugePage) {
        // 128-byte aligned: vertex slots are line pairs and face records lines.
        void* p = std::aligned_alloc(128, (std::max<size_t>(bytes, 1) + 127) / 128 * 128);
        if (!p) throw std::bad_alloc();
        return p;
    }
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
#ifdef __linux__
    madvise(p, rounded, MADV_HUGEPAGE);  // a hint: failure only costs speed
#endif
    return p;
}

namespace {

size_t pow2_at_least(size_t n) { return std::bit_ceil(n < 16 ? size_t{16} : n); }

using io::mix64;

}  // namespace

size_t HalfEdgeBuffer::reserved_bytes(size_t triangle_capacity) {
    const size_t n = triangle_capacity, vertices = 3 * n + 3;
    const size_t hash_slots = pow2_at_least(2 * vertices);
    return n * (sizeof(Face) + 4) + pow2_at_least(2 * n) * sizeof(InteriorEntry) +
           vertices * (sizeof(VertexSlot) + 4 + 4) + hash_slots * 4 + hash_slots / 2 * 4 +
           pow2_at_least(n / 8) * sizeof(Stub);
}

HalfEdgeBuffer::HalfEdgeBuffer(size_t triangle_capacity, double weld_eps)
    : face_capacity_(triangle_capacity),
      // Worst case every in-core face owns three vertices; orphans left by forced writes
      // are evicted when the pool runs short.
      vertex_capacity_(3 * triangle_capacity + 3),
      weld_eps_(weld_eps),
      faces_(raw_array<Face>(triangle_capacity)),
      free_faces_(raw_array<uint32_t>(triangle_capacity)),
      interior_(raw_array<InteriorEntry>(pow2_at_least(2 * triangle_capacity))),
      interior_mask_(pow2_at_least(2 * triangle_capacity) - 1),
      slots_(raw_array<VertexSlot>(vertex_capacity_)),
      free_vertices_(raw_array<uint32_t>(vertex_capacity_)),
      pending_(raw_array<uint32_t>(vertex_capacity_)) {
    // Half-edge indices 4·f + k must stay below the twin markers.
    assert(triangle_capacity >= 4 && triangle_capacity <= (size_t{1} << 30) - 1);
    hash_max_slots_ = pow2_at_least(2 * vertex_capacity_);
    hash_ = raw_array<uint32_t>(hash_max_slots_);
    hash_scratch_ = raw_array<uint32_t>(hash_max_slots_ / 2);
    const size_t slots = std::min<size_t>(hash_max_slots_, 1u << 15);
    std::fill_n(hash_.get(), slots, kNoIndex);
    hash_mask_ = slots - 1;
    const size_t stub_slots = pow2_at_least(triangle_capacity / 8);
    stubs_ = raw_array<Stub>(stub_slots);
    for (size_t i = 0; i < stub_slots; ++i) stubs_[i].a = kNoIndex;
    stub_mask_ = stub_slots - 1;
}

bool HalfEdgeBuffer::same_key(const float a[3], const float b[3]) const {
    if (weld_eps_ == 0) {
        return float_key(a[0]) == float_key(b[0]) && float_key(a[1]) == float_key(b[1]) &&
               float_key(a[2]) == float_key(b[2]);
    }
    for (int i = 0; i < 3; ++i)
        if (weld_cell(a[i]) != weld_cell(b[i])) return false;
    return true;
}

double HalfEdgeBuffer::weld_cell(float x) const {
    // The nearest point of the grid, not the cell below: the cells' borders then lie halfway
    // between grid points. With ⌊x/EPS⌋, coordinates on a multiple of EPS (a floor at z = 0, a
    // CAD part on round numbers) sat on a border, and round-off on either side split them.
    return std::floor(double(x) / weld_eps_ + 0.5);
}

uint64_t HalfEdgeBuffer::cell_hash(const float p[3]) const {
    uint64_t k[3];
    for (int i = 0; i < 3; ++i)
        // The cell index as the bits of the (integral) double: an int64 cast overflows for
        // huge coordinates or tiny cells (fuzz finding, FuzzRegression.Issue7_WeldHugeCoordinate).
        k[i] = std::bit_cast<uint64_t>(weld_cell(p[i]) + 0.0);
    return mix64(k[0] * 0x9e3779b97f4a7c15ull ^ mix64(k[1] + 0x632be59bd9b4e019ull) ^ (k[2] * 0xc2b2ae3d27d4eb4full));
}

void HalfEdgeBuffer::grow_hash() {
    const size_t old_slots = hash_mask_ + 1;
    size_t n = 0;
    for (size_t i = 0; i < old_slots; ++i)
        if (hash_[i] != kNoIndex) hash_scratch_[n++] = hash_[i];
    std::fill_n(hash_.get(), 2 * old_slots, kNoIndex);
    hash_mask_ = 2 * old_slots - 1;
    for (size_t i = 0; i < n; ++i) {
        const uint32_t v = hash_scratch_[i];
        size_t slot = weld_hash(slots_[v].vertex.pos) & hash_mask_;
        while (hash_[slot] != kNoIndex) slot = (slot + 1) & hash_mask_;
        hash_[slot] = v;
    }
}

uint32_t HalfEdgeBuffer::alloc_vertex() {
    assert(vertex_used_ < vertex_capacity_);
    uint32_t v;
    if (free_vertex_stack_ > 0) {
        v = free_vertices_[--free_vertex_stack_];  // generation already bumped by free_vertex
    } else {
        v = vertex_high_++;
        slots_[v].vertex.generation = 1;
    }
    ++vertex_used_;
    if (vertex_used_ > vertex_used_peak_) vertex_used_peak_ = vertex_used_;
    VertexSlot& slot = slots_[v];
    slot.vertex.first_corner = kNoIndex;
    slot.vertex.face_count = 0;
    slot.vertex.open_edges = 0;
    slot.vertex.flags = kAlive;
    slot.vertex.id = 0;
    slot.quadric = Quadric{};
    slot.mark = 0;
    return v;
}

void HalfEdgeBuffer::free_vertex(uint32_t v) {
    Vertex& x = slots_[v].vertex;
    assert(x.face_count == 0 && (x.flags & kInHash) == 0);
    x.flags = 0;
    ++x.generation;
    free_vertices_[free_vertex_stack_++] = v;
    --vertex_used_;
}

uint32_t HalfEdgeBuffer::weld(const float p[3], uint64_t hash) {
    size_t slot = hash & hash_mask_;
    if (weld_eps_ == 0) {
        // Exact welding: vertices in the table keep the position they were entered with,
        // stored with −0 made +0, so comparing raw bits against the normalized key is
        // same_key() without re-normalizing every probed vertex.
        const uint32_t key[3] = {float_key(p[0]), float_key(p[1]), float_key(p[2])};
        for (;;) {
            const uint32_t v = hash_[slot];
            if (v == kNoIndex) break;
            uint32_t stored[3];
            std::memcpy(stored, slots_[v].vertex.pos, sizeof stored);
            if (stored[0] == key[0] && stored[1] == key[1] && stored[2] == key[2]) return v;
            slot = (slot + 1) & hash_mask_;
        }
    }
    for (;;) {
        const uint32_t v = hash_[slot];
        if (v == kNoIndex) break;
        if (same_key(slots_[v].vertex.pos, p)) {
            Vertex& x = slots_[v].vertex;
            if (weld_eps_ != 0 && (x.flags & kWeldMerged) == 0 &&
                (float_key(x.pos[0]) != float_key(p[0]) || float_key(x.pos[1]) != float_key(p[1]) ||
                 float_key(x.pos[2]) != float_key(p[2]))) {
                x.flags |= kWeldMerged;
                ++vertices_merged_;
            }
            return v;
        }
        slot = (slot + 1) & hash_mask_;
    }
    const uint32_t v = alloc_vertex();
    Vertex& x = slots_[v].vertex;
    // The first position seen in a weld cell represents the cell (less distortion than
    // moving every vertex to the grid point).
    for (int i = 0; i < 3; ++i) x.pos[i] = p[i] == 0.0f ? 0.0f : p[i];
    x.flags |= kInHash;
    if (2 * (hash_count_ + 1) > hash_mask_ + 1 && hash_mask_ + 1 < hash_max_slots_) {
        grow_hash();
        slot = hash & hash_mask_;
        while (hash_[slot] != kNoIndex) slot = (slot + 1) & hash_mask_;
    }
    hash_[slot] = v;
    ++hash_count_;
    return v;
}

void HalfEdgeBuffer::hash_erase(uint32_t v) {
    --hash_count_;
    size_t slot = weld_hash(slots_[v].vertex.pos) & hash_mask_;
    while (hash_[slot] != v) {
        assert(hash_[slot] != kNoIndex);
        slot = (slot + 1) & hash_mask_;
    }
    // Backward-shift deletion keeps linear probing free of tombstones.
    size_t hole = slot;
    for (size_t i = (hole + 1) & hash_mask_;; i = (i + 1) & hash_mask_) {
        const uint32_t w = hash_[i];
        if (w == kNoIndex) break;
        const size_t home = weld_hash(slots_[w].vertex.pos) & hash_mask_;
        // Move w into the hole when its home is not cyclically within (hole, i].
        const bool home_in_range = hole <= i ? (home > hole && home <= i) : (home > hole || home <= i);
        if (!home_in_range) {
            hash_[hole] = w;
            hole = i;
        }
    }
    hash_[hole] = kNoIndex;
}

void HalfEdgeBuffer::enter_interior(uint32_t f) {
    if (interior_size_ == interior_mask_ + 1) {
        // Full: drop the entries of faces removed since they were listed, keeping the order.
        // At most face_capacity_ faces are in core, so at least half the ring comes free.
        size_t kept = 0;
        for (size_t i = 0; i < interior_size_; ++i) {
            const InteriorEntry e = interior_[(interior_head_ + i) & interior_mask_];
            if (faces_[e.face].alive && faces_[e.face].born == e.born)
                interior_[(interior_head_ + kept++) & interior_mask_] = e;
        }
        interior_size_ = kept;
        assert(interior_size_ <= interior_mask_);
    }
    interior_[(interior_head_ + interior_size_++) & interior_mask_] = InteriorEntry{f, faces_[f].born};
}

uint32_t HalfEdgeBuffer::oldest_interior_face() {
    while (interior_size_ > 0) {
        const InteriorEntry e = interior_[interior_head_];
        if (faces_[e.face].alive && faces_[e.face].born == e.born) return e.face;
        interior_head_ = (interior_head_ + 1) & interior_mask_;
        --interior_size_;
    }
    return kNoIndex;
}

bool HalfEdgeBuffer::one_fan(uint32_t v) const {
    // Walk round v from its first corner one way (e → twin(prev(e))) until back at the start
    // or at an edge without partner, then the other way (e → next(twin(e))); one fan reaches
    // every face of v.
    const Vertex& x = slots_[v].vertex;
    const uint32_t start = x.first_corner;
    uint32_t count = 1;
    for (uint32_t e = start;;) {
        const uint32_t t = twin(prev_in_face(e));
        if (!is_half_edge(t)) break;
        if (t == start) return count == x.face_count;
        e = t;
        if (++count > x.face_count) return false;
    }
    for (uint32_t e = start;;) {
        const uint32_t t = twin(e);
        if (!is_half_edge(t)) break;
        e = next_in_face(t);
        if (++count > x.face_count) return false;
    }
    return count == x.face_count;
}

bool HalfEdgeBuffer::open_fans(uint32_t v) const {
    // A fan starts at the face whose edge into v (prev→v) has no partner and is walked the other
    // way (e → next(twin(e))), as in one_fan().
    const Vertex& x = slots_[v].vertex;
    uint32_t count = 0;
    for (uint32_t c = x.first_corner; c != kNoIndex; c = next_corner(c)) {
        if (is_half_edge(twin(prev_in_face(c)))) continue;
        for (uint32_t e = c;; e = next_in_face(twin(e))) {
            if (++count > x.face_count) return false;
            if (!is_half_edge(twin(e))) break;
        }
    }
    return count == x.face_count;
}

bool HalfEdgeBuffer::take_written_stub(uint32_t a, uint32_t b) {
    if (stub_count_ == 0) return false;
    const uint32_t ga = slots_[a].vertex.generation, gb = slots_[b].vertex.generation;
    size_t slot = mix64((uint64_t(a) << 32) ^ b) & stub_mask_;
    for (;; slot = (slot + 1) & stub_mask_) {
        Stub& s = stubs_[slot];
        if (s.a == kNoIndex) return false;
        if (s.a == a && s.b == b && s.gen_a == ga && s.gen_b == gb) break;
    }
    // Backward-shift deletion.
    size_t hole = slot;
    for (size_t i = (hole + 1) & stub_mask_;; i = (i + 1) & stub_mask_) {
        const Stub& w = stubs_[i];
        if (w.a == kNoIndex) break;
        const size_t home = mix64((uint64_t(w.a) << 32) ^ w.b) & stub_mask_;
        const bool home_in_range = hole <= i ? (home > hole && home <= i) : (home > hole || home <= i);
        if (!home_in_range) {
            stubs_[hole] = w;
            hole = i;
        }
    }
    stubs_[hole].a = kNoIndex;
    --stub_count_;
    return true;
}

void HalfEdgeBuffer::add_written_stub(uint32_t a, uint32_t b) {
    // Keep the table at most half full; past that the edge simply stays open (its vertices
    // then leave P_in only when finalized).
    if (2 * (stub_count_ + 1) > stub_mask_ + 1) return;
    size_t slot = mix64((uint64_t(a) << 32) ^ b) & stub_mask_;
    while (stubs_[slot].a != kNoIndex) slot = (slot + 1) & stub_mask_;
    stubs_[slot] = Stub{a, slots_[a].vertex.generation, b, slots_[b].vertex.generation};
    ++stub_count_;
}

HalfEdgeBuffer::Added HalfEdgeBuffer::add_triangle(const float tri[9], const uint64_t hashes[3]) {
    assert(!full() && free_vertex_count() >= 3);
    Added added;
    for (int k = 0; k < 3; ++k) added.vertex[k] = weld(tri + 3 * k, hashes ? hashes[k] : weld_hash(tri + 3 * k));
    const uint32_t* v = added.vertex;
    if (!origin_set_) {
        for (int i = 0; i < 3; ++i) origin_[i] = tri[i];
        origin_set_ = true;
    }
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
        added.face = kNoIndex;
        return added;
    }
    // Area-weighted plane quadric, added to all three corners (§4.2).
    double p[3][3];
    for (int k = 0; k < 3; ++k) position(v[k], p[k]);
    const Quadric q = Quadric::from_triangle(p[0], p[1], p[2]);
    for (int k = 0; k < 3; ++k) slots_[v[k]].quadric += q;

    const uint32_t f = free_face_count_ > 0 ? free_faces_[--free_face_count_] : face_high_++;
    ++face_count_;
    Face& added_face = faces_[f];
    added_face.born = ++born_counter_;
    added_face.key[0] = added_face.key[1] = added_face.key[2] = kNotQueued;
    added_face.alive = 1;
    // Connect each half-edge a→b to an open partner b→a. Anything else (a second a→b, or
    // b→a already taken) makes the edge non-manifold: the new half-edge stays unconnected and
    // both ends are frozen against collapses.
    //
    // Walks over two corners' lists find, for every edge, the first existing a→b ("same") and
    // b→a ("opposite") they meet, each edge a→b seen from either end: at a a corner followed
    // by b, at b one preceded by a (the new face is not linked yet, so the lists do not change
    // during the walks). The corner in the most faces is left out: its list is the
    // longest walk and its face records the most cache misses, and at a vertex in thousands
    // of faces (a scanner's invalid points, all written at the origin) walking it for every
    // triangle read there made reading quadratic.
    uint32_t same[3] = {kNoIndex, kNoIndex, kNoIndex}, opposite[3] = {kNoIndex, kNoIndex, kNoIndex};
    uint32_t longest = 0;
    for (uint32_t k = 1; k < 3; ++k)
        if (slots_[v[k]].vertex.face_count > slots_[v[longest]].vertex.face_count) longest = k;
    for (const uint32_t k : {(longest + 1) % 3, (longest + 2) % 3}) {
        const uint32_t k_next = (k + 1) % 3, k_prev = (k + 2) % 3;
        for (uint32_t c = slots_[v[k]].vertex.first_corner; c != kNoIndex;) {
            const Face& face = faces_[face_of(c)];
            const uint32_t j = corner_of(c);
            const uint32_t j_prev = j == 0 ? 2 : j - 1;
            const uint32_t after = face.vertex[j == 2 ? 0 : j + 1], before = face.vertex[j_prev];
            const uint32_t into = half_edge(face_of(c), j_prev);  // before→v[k]
            auto first = [](uint32_t& found, uint32_t h) {
                if (found == kNoIndex) found = h;
            };
            if (after == v[k_next]) first(same[k], c);           // v[k]→v[k+1]
            if (after == v[k_prev]) first(opposite[k_prev], c);  // v[k]→v[k−1]
            if (before == v[k_next]) first(opposite[k], into);   // v[k+1]→v[k]
            if (before == v[k_prev]) first(same[k_prev], into);  // v[k−1]→v[k]
            c = face.next[j];
        }
    }
    for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t a = v[k], b = v[(k + 1) % 3], h = half_edge(f, k);
        faces_[f].vertex[k] = a;
        if (same[k] == kNoIndex && opposite[k] != kNoIndex && twin(opposite[k]) == kOpenEdge) {
            faces_[f].twin[k] = opposite[k];
            set_twin(opposite[k], h);
            --slots_[a].vertex.open_edges;
            --slots_[b].vertex.open_edges;
        } else if (same[k] == kNoIndex && opposite[k] == kNoIndex) {
            if (take_written_stub(b, a)) {
                faces_[f].twin[k] = kWrittenEdge;  // the partner was force-written earlier
                --slots_[a].vertex.open_edges;
                --slots_[b].vertex.open_edges;
            } else {
                faces_[f].twin[k] = kOpenEdge;
                ++slots_[a].vertex.open_edges;
                ++slots_[b].vertex.open_edges;
            }
        } else {
            faces_[f].twin[k] = kNonManifoldEdge;
            slots_[a].vertex.flags |= kNonManifold;
            slots_[b].vertex.flags |= kNonManifold;
            ++nonmanifold_edges_;
        }
    }
    for (uint32_t k = 0; k < 3; ++k) link_corner(v[k], half_edge(f, k));
    // Every corner was found through (or entered into) the hash table, so all three are on
    // P_in; vertices whose fan just closed leave it.
    added_face.pin_count = 3;
    ++pinned_face_count_;
    for (int k = 0; k < 3; ++k)
        if (slots_[v[k]].vertex.open_edges == 0) finalize_vertex(v[k]);
    added.face = f;
    return added;
}

void HalfEdgeBuffer::finalize_vertex(uint32_t v) {
    Vertex& x = slots_[v].vertex;
    if ((x.flags & kInHash) == 0) return;
    // Its open edges are final now (no input reaches v any more): a true boundary. Add Garland
    // & Heckbert's perpendicular boundary planes to both ends, once per edge: when the other
    // end is still on P_in (it skips the edge when finalized later, v being off P_in then).
    for (uint32_t c = x.first_corner; c != kNoIndex; c = next_corner(c)) {
        const uint32_t e[2] = {c, prev_in_face(c)};  // v→next and prev→v
        for (uint32_t h : e) {
            if (twin(h) != kOpenEdge) continue;
            const uint32_t a = corner_vertex(h), b = corner_vertex(next_in_face(h));
            const uint32_t other = a == v ? b : a;
            if (other == v || (slots_[other].vertex.flags & kInHash) == 0) continue;
            double pa[3], pb[3], pc[3];
            position(a, pa);
            position(b, pb);
            position(corner_vertex(prev_in_face(h)), pc);
            const Quadric penalty = Quadric::from_boundary_edge(pa, pb, pc);
            slots_[a].quadric += penalty;
            slots_[b].quadric += penalty;
            ++boundary_edges_;
        }
    }
    hash_erase(v);
    x.flags &= ~kInHash;
    if (x.face_count == 0) {
        free_vertex(v);
        return;
    }
    for (uint32_t c = x.first_corner; c != kNoIndex; c = next_corner(c))
        if (--faces_[face_of(c)].pin_count == 0) {
            --pinned_face_count_;
            enter_interior(face_of(c));
        }
    // A vertex where two fans touch is no manifold vertex: it moves only when every fan is open
    // (boundary loops touching there, collapse.hpp). Finding out now, once, spares every
    // collapse the walks.
    classify_fans(v);
    mark_pending(v);
}

void HalfEdgeBuffer::freeze(uint32_t v, uint64_t id) {
    Vertex& x = slots_[v].vertex;
    assert((x.flags & kFrozen) == 0);
    x.flags |= kFrozen;
    x.id = id;
    mark_pending(v);
}

void HalfEdgeBuffer::link_corner(uint32_t v, uint32_t c) {
    Vertex& x = slots_[v].vertex;
    Face& face = faces_[face_of(c)];
    face.next[corner_of(c)] = x.first_corner;
    face.prev[corner_of(c)] = kNoIndex;
    if (x.first_corner != kNoIndex) faces_[face_of(x.first_corner)].prev[corner_of(x.first_corner)] = c;
    x.first_corner = c;
    ++x.face_count;
}

void HalfEdgeBuffer::unlink_corner(uint32_t v, uint32_t c) {
    Vertex& x = slots_[v].vertex;
    const Face& face = faces_[face_of(c)];
    const uint32_t next = face.next[corner_of(c)], prev = face.prev[corner_of(c)];
    if (prev == kNoIndex)
        x.first_corner = next;
    else
        faces_[face_of(prev)].next[corner_of(prev)] = next;
    if (next != kNoIndex) faces_[face_of(next)].prev[corner_of(next)] = prev;
    --x.face_count;
}

void HalfEdgeBuffer::detach_face(uint32_t f) {
    for (uint32_t k = 0; k < 3; ++k) unlink_corner(faces_[f].vertex[k], half_edge(f, k));
    faces_[f].alive = 0;
    --face_count_;
    if (faces_[f].pin_count > 0) --pinned_face_count_;
    free_faces_[free_face_count_++] = f;
}

void HalfEdgeBuffer::move_corners(uint32_t p, uint32_t q) {
    Vertex& from = slots_[p].vertex;
    uint32_t c = from.first_corner;
    while (c != kNoIndex) {
        const uint32_t next = next_corner(c);
        faces_[face_of(c)].vertex[corner_of(c)] = q;
        link_corner(q, c);  // at the head of q's list, in p's order reversed
        c = next;
    }
    from.first_corner = kNoIndex;
    from.face_count = 0;
}

void HalfEdgeBuffer::finalize_all() {
    for (uint32_t v = 0; v < vertex_high_; ++v)
        if ((slots_[v].vertex.flags & (kAlive | kInHash)) == (kAlive | kInHash)) finalize_vertex(v);
}

size_t HalfEdgeBuffer::evict_orphans() {
    size_t evicted = 0;
    for (uint32_t v = 0; v < vertex_high_; ++v) {
        const Vertex& x = slots_[v].vertex;
        if ((x.flags & (kAlive | kInHash)) == (kAlive | kInHash) && x.face_count == 0) {
            finalize_vertex(v);
            ++evicted;
        }
    }
    return evicted;
}

}  // namespace meshstream::decimate
