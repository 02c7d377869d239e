// The in-core portion of the mesh (Wu & Kobbelt 2003, §4 and §4.2): a half-edge mesh over
// fixed-capacity pools, allocated once for `--buffer N` triangles and reused for the whole
// stream. Half-edge h = 4·f + k (k < 3; a power-of-two stride, so no division by 3 on every
// access) runs from corner k of face f to corner (k+1) mod 3; its twin
// is the opposite half-edge of the neighbouring face or one of three markers:
//   kOpenEdge        no partner yet: the edge lies on P_in (towards unread input) or on a hole,
//   kWrittenEdge     the partner was written (the edge lies on P_out),
//   kNonManifoldEdge a third face on an edge, a duplicate or an orientation conflict: frozen.
// Every vertex also keeps a singly linked list of its corners, so its full neighbourhood is
// known even where the input is not manifold (the link condition needs that).
//
// READ (§4.2) welds vertices on exact position (or on a grid of `weld_eps`) through an
// open-addressing hash table that holds only vertices still open towards unread input (P_in):
// a vertex leaves the table once every incident edge has a partner, or when it is finalized
// (end of input, sorted sweep, eviction). Each incoming triangle adds its area-weighted plane
// quadric to its three vertices.
//
// Two dense index sets serve the writer (§4.4): faces touching no P_in vertex ("interior"),
// and the subset of those touching P_out (a frozen, already written vertex).
//
// Layout (the pools are far larger than the caches and are read at random, so the number of
// distinct cache lines touched per operation is what costs): everything about a face — its
// three corner vertices, twins, both corner-list links and its places in the face sets — is
// one 64-byte line; everything about a vertex — the record, the walk stamp and its quadric —
// is one 128-byte pair of lines.
//
// Memory bound: for capacity N triangles, 64·N bytes of faces plus 12·N of face sets and free
// list, 3·N+3 vertex slots of 128 + 4 bytes and a 4-byte hash slot per 1/2 vertex: about
// 490·N bytes reserved, of which only the touched part becomes resident (pools hand out the
// most recently freed slot first, and a manifold buffer holds about N/2 vertices).
#pragma once

#include "decimate/quadric.hpp"

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>

namespace meshstream::decimate {

inline constexpr uint32_t kNoIndex = 0xFFFFFFFFu;
inline constexpr uint32_t kOpenEdge = 0xFFFFFFFFu;
inline constexpr uint32_t kWrittenEdge = 0xFFFFFFFEu;
inline constexpr uint32_t kNonManifoldEdge = 0xFFFFFFFDu;
// True when `twin` names a real half-edge rather than one of the markers.
inline bool is_half_edge(uint32_t twin) { return twin < kNonManifoldEdge; }
// Half-edge / corner k (0..2) of face f, and back.
inline uint32_t half_edge(uint32_t f, uint32_t k) { return 4 * f + k; }
inline uint32_t face_of(uint32_t h) { return h >> 2; }
inline uint32_t corner_of(uint32_t h) { return h & 3; }
// A table rather than a choice: g++ compiled `(h & 3) == 2 ? h - 2 : h + 1` to a branch in
// the fan walks, where it mispredicted often (corner k = h & 3 is 0, 1 or 2).
inline constexpr int8_t kToNextInFace[4] = {1, 1, -2, 0}, kToPrevInFace[4] = {2, -1, -1, 0};
inline uint32_t next_in_face(uint32_t h) { return h + kToNextInFace[h & 3]; }
inline uint32_t prev_in_face(uint32_t h) { return h + kToPrevInFace[h & 3]; }

// Vertex flags.
inline constexpr uint8_t kInHash = 1;        // open towards unread input: on P_in
inline constexpr uint8_t kFrozen = 2;        // written (on P_out): position final, id assigned
inline constexpr uint8_t kNonManifold = 4;   // touches a non-manifold edge: never collapsed
inline constexpr uint8_t kWeldMerged = 8;    // absorbed another input position (--weld)
inline constexpr uint8_t kAlive = 16;
inline constexpr uint8_t kHasPartner = 32;  // partner_position() holds a collapsed edge's far end

struct Vertex {
    float pos[3];           // input position, moved once when written (§4.4)
    uint32_t first_corner;  // head of the corner list (kNoIndex when no face)
    uint32_t face_count;
    uint32_t open_edges;    // incident half-edges without partner (kOpenEdge), also written ones
    uint32_t generation;    // bumped at every allocation (stale references detect reuse)
    uint8_t flags;
    union {
        uint64_t id;               // output vertex id, valid once kFrozen
        float partner_xy[2];       // before freezing: see HalfEdgeBuffer::partner_position
    };
};

// An array of an implicit-lifetime type left uninitialized, so that pages nobody touches
// never become resident (new T[n] would value-initialize types with member initializers).
// Large arrays are 2 MiB aligned and advised as transparent huge pages: the pools are read
// at random, and with 4 KiB pages nearly every access would also miss the TLB.
struct FreeDeleter {
    void operator()(void* p) const { std::free(p); }
};
template <class T> using RawArray = std::unique_ptr<T[], FreeDeleter>;
void* allocate_pool(size_t bytes);  // throws std::bad_alloc
template <class T> RawArray<T> raw_array(size_t n) {
    return RawArray<T>(static_cast<T*>(allocate_pool(n * sizeof(T))));
}

// Everything about one face, in one cache line. Corner k of face f is corner 4·f + k, which is
// also the half-edge from corner k to corner (k+1) mod 3.
struct alignas(64) Face {
    uint32_t vertex[3];     // corner → vertex
    uint32_t twin[3];       // half-edge → twin half-edge or marker
    uint32_t next[3];       // corner → next corner of the same vertex (kNoIndex: last)
    uint32_t prev[3];       // corner → previous corner of the same vertex (kNoIndex: first)
    uint32_t where[3];      // index in the live, interior and frontier FaceSets (kNoIndex: absent)
    uint8_t pin_count;      // vertices on P_in
    uint8_t touches_out;    // has a frozen vertex
};
static_assert(sizeof(Face) == 64);

// A set of face indices with O(1) insert, erase and uniform sampling. The item array is dense;
// a face's index in it is kept in the face record (Face::where[slot]).
class FaceSet {
public:
    FaceSet(size_t capacity, Face* faces, int slot);
    bool contains(uint32_t f) const { return faces_[f].where[slot_] != kNoIndex; }
    void insert(uint32_t f) {
        uint32_t& w = faces_[f].where[slot_];
        if (w != kNoIndex) return;
        w = static_cast<uint32_t>(size_);
        items_[size_++] = f;
    }
    void erase(uint32_t f) {
        uint32_t& w = faces_[f].where[slot_];
        if (w == kNoIndex) return;
        const uint32_t i = w;
        const uint32_t last = items_[--size_];
        items_[i] = last;
        faces_[last].where[slot_] = i;
        w = kNoIndex;
    }
    // Call when slot f is (re)allocated: marks it absent.
    void reset(uint32_t f) { faces_[f].where[slot_] = kNoIndex; }
    size_t size() const { return size_; }
    uint32_t at(size_t i) const { return items_[i]; }
    void prefetch(size_t i) const { __builtin_prefetch(&items_[i]); }

private:
    RawArray<uint32_t> items_;
    Face* faces_;
    int slot_;
    size_t size_ = 0;
};

class HalfEdgeBuffer {
public:
    // `triangle_capacity` ≥ 4. `weld_eps` = 0: weld on exact float position (−0 equals +0);
    // > 0: weld positions nearest to the same point of a grid of that size.
    HalfEdgeBuffer(size_t triangle_capacity, double weld_eps);
    // The address space the constructor reserves for `triangle_capacity` (about 500 bytes a
    // triangle); the hash and stub tables of it are resident at once, the pools when touched.
    static size_t reserved_bytes(size_t triangle_capacity);

    size_t face_capacity() const { return face_capacity_; }
    size_t face_count() const { return live_.size(); }
    bool full() const { return live_.size() == face_capacity_; }
    // Free vertex slots; add_triangle needs 3.
    size_t free_vertex_count() const { return vertex_capacity_ - vertex_used_; }

    struct Added {
        uint32_t face;     // kNoIndex when degenerate (two corners welded to one vertex)
        uint32_t vertex[3];
    };
    // READ(1) of §4.2: welds the corners, accumulates quadrics, connects the new face to
    // its in-core neighbours. Preconditions: !full(), free_vertex_count() ≥ 3. A degenerate
    // triangle is not inserted (its vertices are, so the caller can pass it through).
    Added add_triangle(const float tri[9]) { return add_triangle(tri, nullptr); }
    // The same with the corners' welding hash slots precomputed by weld_slots() (or null).
    Added add_triangle(const float tri[9], const size_t slots[3]);
    // The welding hash slots of a triangle's corners (a pure function of the positions).
    void weld_slots(const float tri[9], size_t slots[3]) const {
        for (int k = 0; k < 3; ++k) slots[k] = hash_slot(tri + 3 * k);
    }

    // The vertex leaves P_in (no more input will reach it): removed from the hash table; a
    // vertex without faces is freed.
    void finalize_vertex(uint32_t v);
    // Marks the vertex written (P_out) with output id `id`.
    void freeze(uint32_t v, uint64_t id);
    // Removes face f from the vertex lists and sets and frees it. Twins and open-edge counts
    // are the caller's business. Vertices left without faces are not freed here.
    void detach_face(uint32_t f);
    // Re-points every corner of p to q (the vertex part of a half-edge collapse p→q).
    void move_corners(uint32_t p, uint32_t q);
    void free_vertex(uint32_t v);
    // Records that the written face's half-edge a→b had no partner, so that the matching
    // half-edge b→a arriving later is connected to P_out instead of staying open forever.
    void add_written_stub(uint32_t a, uint32_t b);
    // Frees vertices that are open towards input but have no face left (left behind by
    // forced writes); returns how many.
    size_t evict_orphans();
    // End of input: every vertex still on P_in becomes true boundary (finalize_vertex).
    void finalize_all();

    // Accessors.
    uint32_t corner_vertex(uint32_t h) const { return faces_[face_of(h)].vertex[corner_of(h)]; }
    uint32_t twin(uint32_t h) const { return faces_[face_of(h)].twin[corner_of(h)]; }
    // Cache prefetch hints for batched random sampling (no effect on results).
    void prefetch_face(uint32_t f) const { __builtin_prefetch(&faces_[f]); }
    void prefetch_vertex(uint32_t v) const {
        __builtin_prefetch(&slots_[v]);
        __builtin_prefetch(reinterpret_cast<const char*>(&slots_[v]) + 64);
    }
    // Prefetch hints for reading a triangle soon, given its weld_slots(): `stage` 0 fetches
    // the hash slots, stage 1 (a few triangles later, once the slots are cached) the vertices
    // they name. Hints only: the table may change before the triangle is read.
    void prefetch_triangle(const size_t slots[3], int stage) const {
        for (int k = 0; k < 3; ++k) {
            if (stage == 0) {
                __builtin_prefetch(&hash_[slots[k]]);
            } else {
                // An empty slot prefetches vertex 0 instead of branching: whether a corner is
                // new is a coin toss to the branch predictor.
                const uint32_t v = hash_[slots[k]];
                prefetch_vertex(v != kNoIndex ? v : 0);
            }
        }
    }
    void set_twin(uint32_t h, uint32_t t) { faces_[face_of(h)].twin[corner_of(h)] = t; }
    uint32_t next_corner(uint32_t c) const { return faces_[face_of(c)].next[corner_of(c)]; }
    Vertex& vertex(uint32_t v) { return slots_[v].vertex; }
    const Vertex& vertex(uint32_t v) const { return slots_[v].vertex; }
    Quadric& quadric(uint32_t v) { return slots_[v].quadric; }
    const Quadric& quadric(uint32_t v) const { return slots_[v].quadric; }
    // The point positions (position()) and quadrics are relative to: the first vertex read, so
    // that large scan coordinates do not cancel catastrophically.
    double origin(int axis) const { return origin_[axis]; }
    // Position relative to origin() in double (what quadrics are expressed in).
    void position(uint32_t v, double out[3]) const {
        const float* pos = slots_[v].vertex.pos;
        for (int i = 0; i < 3; ++i) out[i] = double(pos[i]) - origin_[i];
    }
    // The position (relative to origin()) of the vertex p last collapsed into v, the far end
    // of that edge: a fallback placement when v's quadric has no unique minimum (§4.4).
    // Returns false when nothing was collapsed into v. Valid until v is frozen.
    bool partner_position(uint32_t v, double out[3]) const {
        const VertexSlot& slot = slots_[v];
        if ((slot.vertex.flags & kHasPartner) == 0) return false;
        const float pos[3] = {slot.vertex.partner_xy[0], slot.vertex.partner_xy[1], slot.partner_z};
        for (int i = 0; i < 3; ++i) out[i] = double(pos[i]) - origin_[i];
        return true;
    }
    void set_partner(uint32_t v, const float pos[3]) {
        VertexSlot& slot = slots_[v];
        slot.vertex.partner_xy[0] = pos[0];
        slot.vertex.partner_xy[1] = pos[1];
        slot.partner_z = pos[2];
        slot.vertex.flags |= kHasPartner;
    }
    void set_position(uint32_t v, const double rel[3]) {
        ++edits_;
        for (int i = 0; i < 3; ++i) slots_[v].vertex.pos[i] = float(rel[i] + origin_[i]);
    }
    // Rounds a relative position to what set_position() would store (float coordinates), so
    // that geometric checks see exactly the position a vertex will get.
    void round_position(double rel[3]) const {
        for (int i = 0; i < 3; ++i) rel[i] = through_float(rel[i] + origin_[i]) - origin_[i];
    }
    // double(float(x)), kept from being optimized away: g++ 12's SLP vectorizer dropped the
    // float conversion of two of the three coordinates in round_position() as inlined into
    // collapse_placement() at -O3 (checked on its object code), so checks saw positions that
    // set_position() would not store. The empty asm makes the float a value the compiler
    // cannot see through (at no cost on x86-64: no store, no load).
    static double through_float(double x) {
        float f = static_cast<float>(x);
#if defined(__GNUC__) && defined(__x86_64__)
        asm("" : "+x"(f));  // stays in its SSE register
#elif defined(__GNUC__)
        asm("" : "+m"(f));
#endif
        return f;
    }
    const FaceSet& live_faces() const { return live_; }
    const FaceSet& interior_faces() const { return interior_; }  // no P_in vertex
    const FaceSet& frontier_faces() const { return frontier_; }  // interior and touching P_out
    // A fresh mark value for stamp(): vertices stamped with it are "in the current set".
    uint32_t new_stamp() {
        if (++stamp_counter_ == 0) {  // wrapped: old marks could alias
            for (uint32_t v = 0; v < vertex_high_; ++v) slots_[v].stamp = 0;
            stamp_counter_ = 1;
        }
        return stamp_counter_;
    }
    uint32_t& stamp(uint32_t v) { return slots_[v].stamp; }

    // Counts structural edits (reads, finalizations, writes, face removals, moves): equal
    // counts mean nothing changed in between, so ratings computed then are still exact.
    uint64_t edits() const { return edits_; }

    // Running counts for Stats.
    uint64_t vertices_merged() const { return vertices_merged_; }
    uint64_t nonmanifold_edges() const { return nonmanifold_edges_; }
    // Edges left without a partner when their vertices left P_in: true boundary (hole rims,
    // open borders, cracks between triangles that share no corner).
    uint64_t boundary_edges() const { return boundary_edges_; }
    size_t peak_vertices() const { return vertex_used_peak_; }

private:
    uint32_t weld(const float p[3], size_t slot);
    uint32_t alloc_vertex();
    void update_face_sets(uint32_t f);
    void hash_erase(uint32_t v);
    size_t hash_slot(const float p[3]) const;
    bool same_key(const float a[3], const float b[3]) const;
    double weld_cell(float x) const;  // grid index (an integral double) of a coordinate
    bool take_written_stub(uint32_t a, uint32_t b);

    size_t face_capacity_, vertex_capacity_;
    double weld_eps_;
    bool origin_set_ = false;
    double origin_[3] = {0, 0, 0};

    // Everything about one vertex, in one 128-byte pair of cache lines.
    struct alignas(128) VertexSlot {
        Vertex vertex;
        uint32_t stamp;
        float partner_z;  // with Vertex::partner_xy
        Quadric quadric;
    };
    static_assert(sizeof(VertexSlot) == 128);

    void link_corner(uint32_t v, uint32_t c);
    void unlink_corner(uint32_t v, uint32_t c);

    RawArray<Face> faces_;
    RawArray<uint32_t> free_faces_;
    size_t free_face_count_ = 0;
    uint32_t face_high_ = 0;
    FaceSet live_, interior_, frontier_;

    RawArray<VertexSlot> slots_;
    RawArray<uint32_t> free_vertices_;
    size_t free_vertex_stack_ = 0;
    uint32_t vertex_high_ = 0;
    size_t vertex_used_ = 0, vertex_used_peak_ = 0;
    uint32_t stamp_counter_ = 0;

    RawArray<uint32_t> hash_;  // vertex index or kNoIndex; linear probing
    size_t hash_mask_;

    struct Stub { uint32_t a, gen_a, b, gen_b; };
    RawArray<Stub> stubs_;  // a == kNoIndex: empty; linear probing
    size_t stub_mask_, stub_count_ = 0;

    uint64_t vertices_merged_ = 0, nonmanifold_edges_ = 0, boundary_edges_ = 0;
    uint64_t edits_ = 0;
};

}  // namespace meshstream::decimate
