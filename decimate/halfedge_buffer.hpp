// The in-core portion of the mesh (Wu & Kobbelt 2003, §4 and §4.2): a half-edge mesh over
// fixed-capacity pools, allocated once for `--buffer N` triangles and reused for the whole
// stream. Half-edge h = 4·f + k (k < 3; a power-of-two stride, so no division by 3 on every
// access) runs from corner k of face f to corner (k+1) mod 3; its twin
// is the opposite half-edge of the neighbouring face or one of three markers:
//   kOpenEdge        no partner yet: the edge lies on P_in (towards unread input) or on a hole,
//   kWrittenEdge     the partner was written (the edge lies on P_out),
//   kNonManifoldEdge a third face on an edge, a duplicate or an orientation conflict: frozen.
// Every vertex also keeps a doubly linked list of its corners, so its full neighbourhood is
// known even where the input is not manifold (the link condition needs that).
//
// READ (§4.2) welds vertices on exact position (or on a grid of `weld_eps`) through an
// open-addressing hash table that holds only vertices still open towards unread input (P_in):
// a vertex leaves the table once every incident edge has a partner, or when it is finalized
// (end of input, sorted sweep, eviction). Each incoming triangle adds its plane quadric to its
// three vertices.
//
// Two lists tell the decimator what changed: vertices whose collapses need rating (they left
// P_in or were written: take_pending()), and faces that left P_in, oldest first (the write
// order, oldest_interior_face()). Each face record also holds the collapse queue's key of its
// three half-edges (collapse_queue.hpp).
//
// Layout (the pools are far larger than the caches and are read at random, so the number of
// distinct cache lines touched per operation is what costs): everything about a face — its
// three corner vertices, twins, both corner-list links and its queue keys — is one 64-byte
// line; everything about a vertex — the record, a mark and its quadric — is one 128-byte pair
// of lines.
//
// Memory bound: for capacity N triangles, 64·N bytes of faces plus 4·N of free list and up to
// 32·N of interior order, 3·N+3 vertex slots of 128 + 8 bytes (free list, pending list) and
// 12–24 bytes of welding hash per vertex (the table and half as much to rehash through),
// a 16-byte stub slot per N/8 to N/4 triangles: about 560·N bytes reserved, of which only the
// touched part becomes resident (pools hand out the most recently freed slot first, a manifold
// buffer holds about N/2 vertices, and the hash table grows with P_in).
#pragma once

#include "decimate/quadric.hpp"

#include <algorithm>
#include <bit>
#include <cstddef>
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
inline constexpr uint16_t kInHash = 1;       // open towards unread input: on P_in
inline constexpr uint16_t kFrozen = 2;       // written (on P_out): position final, id assigned
inline constexpr uint16_t kNonManifold = 4;  // touches a non-manifold edge: never collapsed
inline constexpr uint16_t kWeldMerged = 8;   // absorbed another input position (--weld)
inline constexpr uint16_t kAlive = 16;
inline constexpr uint16_t kHasPartner = 32;   // partner_position() holds a collapsed edge's far end
inline constexpr uint16_t kPending = 64;      // listed for take_pending()
inline constexpr uint16_t kBlocked = 128;     // a collapse at it was refused (collapse.hpp)
inline constexpr uint16_t kManyFans = 256;    // its faces are not one fan (two fans touch here)
inline constexpr uint16_t kSeam = 512;        // its corners disagree in attributes (attribute_store.hpp)
inline constexpr uint16_t kHasValues = 1024;  // its attribute record is set up (attribute_store.hpp)
// With kManyFans: every fan is open, so the fans meet at this vertex only (boundary loops that
// touch here), and the vertex may slide along a boundary edge (collapse.hpp).
inline constexpr uint16_t kOpenFans = 2048;
// The seam pass (Part::kSeams): made by a triangle that stands for itself (a range's seam piece,
// at full resolution) and in no triangle that stands for more (a range's decimated interior).
// A vertex along a seam; see set_full_resolution_first().
inline constexpr uint16_t kFullResolution = 4096;

struct Vertex {
    float pos[3];           // input position, moved by collapses and once when written (§4.4)
    uint32_t first_corner;  // head of the corner list (kNoIndex when no face)
    uint32_t face_count;
    uint32_t open_edges;  // incident half-edges without partner (kOpenEdge), also written ones
    uint32_t generation;  // bumped at every allocation (stale references detect reuse)
    uint16_t flags;
    union {
        uint64_t id;          // output vertex id, valid once kFrozen
        float partner_xy[2];  // before freezing: see HalfEdgeBuffer::partner_position
    };
};

// An array of an implicit-lifetime type left uninitialized, so that pages nobody touches
// never become resident (new T[n] would value-initialize types with member initializers).
// Large arrays are 2 MiB aligned and advised as transparent huge pages: the pools are read
// at random, and with 4 KiB pages nearly every access would also miss the TLB.
struct FreeDeleter {
    void operator()(void* p) const { std::free(p); }
};
template <class T>
using RawArray = std::unique_ptr<T[], FreeDeleter>;
void* allocate_pool(size_t bytes);  // throws std::bad_alloc
template <class T>
RawArray<T> raw_array(size_t n) {
    return RawArray<T>(static_cast<T*>(allocate_pool(n * sizeof(T))));
}

// The queue key of a half-edge that is not queued (collapse_queue.hpp).
inline constexpr uint16_t kNotQueued = 0xFFFF;

// Everything about one face, in one cache line. Corner k of face f is corner 4·f + k, which is
// also the half-edge from corner k to corner (k+1) mod 3.
struct alignas(64) Face {
    uint32_t vertex[3];  // corner → vertex
    uint32_t twin[3];    // half-edge → twin half-edge or marker
    uint32_t next[3];    // corner → next corner of the same vertex (kNoIndex: last)
    uint32_t prev[3];    // corner → previous corner of the same vertex (kNoIndex: first)
    uint32_t born;       // creation serial: tells a reused slot from the face listed before
    uint16_t key[3];     // collapse queue key of half-edge k's edge, or kNotQueued
    uint8_t pin_count;   // vertices on P_in
    uint8_t alive;
};
static_assert(sizeof(Face) == 64);

class AttributeStore;

class HalfEdgeBuffer {
public:
    // `triangle_capacity` ≥ 4. `weld_eps` = 0: weld on exact float position (−0 equals +0);
    // > 0: weld positions nearest to the same point of a grid of that size.
    HalfEdgeBuffer(size_t triangle_capacity, double weld_eps);
    // The address space the constructor reserves for `triangle_capacity` (about 560 bytes a
    // triangle); the stub table is resident at once, the welding hash as it grows, the pools
    // when touched.
    static size_t reserved_bytes(size_t triangle_capacity);

    size_t face_capacity() const { return face_capacity_; }
    size_t face_count() const { return face_count_; }
    bool full() const { return face_count_ == face_capacity_; }
    // Faces added so far (the creation serial of the last: Face::born, which wraps at 2^32).
    uint32_t faces_added() const { return born_counter_; }
    // Faces with a corner on P_in (the rest are interior: oldest_interior_face()).
    size_t pinned_face_count() const { return pinned_face_count_; }
    // Vertices on P_in (those still open towards input, in the welding hash table).
    size_t open_vertex_count() const { return hash_count_; }
    // While set, only edges with an end flagged kFullResolution are rated for collapse
    // (greedy.cpp, rate_edge); the others are left out of the queue. The seam pass decimates
    // its full-resolution seams first: the ranges' interiors it reads are at the ratio already,
    // and their quadrics hold only the planes of the decimated triangles, which make a collapse
    // there look cheaper than it is.
    bool full_resolution_first() const { return full_resolution_first_; }
    void set_full_resolution_first(bool on) { full_resolution_first_ = on; }
    // Free vertex slots; add_triangle needs 3.
    size_t free_vertex_count() const { return vertex_capacity_ - vertex_used_; }
    // Face slots [0, face_slots()) have been used; face_alive() tells which hold a face.
    uint32_t face_slots() const { return face_high_; }
    // Vertex slots [0, vertex_slots()) have been used; kAlive tells which hold a vertex.
    uint32_t vertex_slots() const { return vertex_high_; }
    bool face_alive(uint32_t f) const { return faces_[f].alive != 0; }

    struct Added {
        uint32_t face;  // kNoIndex when degenerate (two corners welded to one vertex)
        uint32_t vertex[3];
    };
    // READ(1) of §4.2: welds the corners, accumulates quadrics, connects the new face to
    // its in-core neighbours. Preconditions: !full(), free_vertex_count() ≥ 3. A degenerate
    // triangle is not inserted (its vertices are, so the caller can pass it through).
    Added add_triangle(const float tri[9]) { return add_triangle(tri, nullptr); }
    // The same with the corners' welding hashes precomputed by weld_hashes() (or null).
    Added add_triangle(const float tri[9], const uint64_t hashes[3]);
    // The welding hashes of a triangle's corners (a pure function of the positions).
    void weld_hashes(const float tri[9], uint64_t hashes[3]) const {
        for (int k = 0; k < 3; ++k) hashes[k] = weld_hash(tri + 3 * k);
    }

    // The vertex leaves P_in (no more input will reach it): removed from the hash table, its
    // open edges become boundary (quadric planes added), its faces may become interior; it is
    // listed for take_pending(). A vertex without faces is freed.
    void finalize_vertex(uint32_t v);
    // Marks the vertex written (P_out) with output id `id`, and lists it for take_pending()
    // (collapses into it are rated differently now).
    void freeze(uint32_t v, uint64_t id);
    // Walks v's fans again and sets kManyFans (its faces are not one fan) and kOpenFans (with
    // it: every fan open) as they are now; finalize_vertex() does so once, and a collapse that
    // closes a hole (collapse.hpp, closed_hole) where the fans at v have changed.
    void classify_fans(uint32_t v) {
        Vertex& x = slots_[v].vertex;
        x.flags &= ~(kManyFans | kOpenFans);
        if (x.face_count > 0 && !one_fan(v)) x.flags |= open_fans(v) ? kManyFans | kOpenFans : kManyFans;
    }
    // Removes face f from the vertex lists and frees it. Twins and open-edge counts are the
    // caller's business. Vertices left without faces are not freed here.
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

    // The face that left P_in first among those still in core (all three corners off P_in),
    // or kNoIndex when every face touches P_in. Faces leave the order only when removed.
    uint32_t oldest_interior_face();

    // Vertices whose collapses need (re)rating: marks v (at most one entry per vertex until
    // taken). finalize_vertex() and freeze() mark; so do collapses that change a neighbour.
    void mark_pending(uint32_t v) {
        Vertex& x = slots_[v].vertex;
        if (x.flags & kPending) return;
        x.flags |= kPending;
        if (pending_count_ < vertex_capacity_)
            pending_[pending_count_++] = v;
        else
            pending_overflow_ = true;  // take_pending() then scans every vertex
    }
    bool has_pending() const { return pending_count_ > 0 || pending_overflow_; }
    // Calls f(v) for each marked vertex still alive, unmarking it, and empties the list.
    template <class F>
    void take_pending(F&& f) {
        auto take = [&](uint32_t v) {
            Vertex& x = slots_[v].vertex;
            if ((x.flags & (kPending | kAlive)) != (kPending | kAlive)) return;
            x.flags &= ~kPending;
            f(v);
        };
        if (pending_overflow_) {
            for (uint32_t v = 0; v < vertex_high_; ++v) take(v);
        } else {
            for (size_t i = 0; i < pending_count_; ++i) take(pending_[i]);
        }
        pending_count_ = 0;
        pending_overflow_ = false;
    }

    // Accessors.
    uint32_t corner_vertex(uint32_t h) const { return faces_[face_of(h)].vertex[corner_of(h)]; }
    uint32_t twin(uint32_t h) const { return faces_[face_of(h)].twin[corner_of(h)]; }
    uint16_t& queue_key(uint32_t h) { return faces_[face_of(h)].key[corner_of(h)]; }
    uint16_t queue_key(uint32_t h) const { return faces_[face_of(h)].key[corner_of(h)]; }
    const Face& face(uint32_t f) const { return faces_[f]; }
    // Cache prefetch hints (no effect on results).
    void prefetch_face(uint32_t f) const { __builtin_prefetch(&faces_[f]); }
    void prefetch_vertex(uint32_t v) const {
        __builtin_prefetch(&slots_[v]);
        __builtin_prefetch(reinterpret_cast<const char*>(&slots_[v]) + 64);
    }
    // Prefetch hints for reading a triangle soon, given its weld_hashes(): `stage` 0 fetches
    // the hash slots, stage 1 (a few triangles later, once the slots are cached) the vertices
    // they name. Hints only: the table may change before the triangle is read.
    void prefetch_triangle(const uint64_t hashes[3], int stage) const {
        for (int k = 0; k < 3; ++k) {
            if (stage == 0) {
                __builtin_prefetch(&hash_[hashes[k] & hash_mask_]);
            } else {
                prefetch_vertex(welded_hint(hashes[k]));
            }
        }
    }
    // The slot a new vertex gets `ahead` allocations from now if no vertex is freed meanwhile,
    // for a prefetch hint: a new vertex's records are written at once, and a freed slot has
    // mostly left the cache since it was written out.
    uint32_t allocation_hint(size_t ahead) const {
        if (ahead < free_vertex_stack_) return free_vertices_[free_vertex_stack_ - 1 - ahead];
        return uint32_t(std::min<size_t>(vertex_high_ + (ahead - free_vertex_stack_), vertex_capacity_ - 1));
    }
    // The vertex a corner of weld hash `hash` would probably weld to, for a prefetch hint (the
    // first of its probe sequence); an empty slot gives vertex 0 instead of a branch: whether a
    // corner is new is a coin toss to the branch predictor.
    uint32_t welded_hint(uint64_t hash) const {
        const uint32_t v = hash_[hash & hash_mask_];
        return v != kNoIndex ? v : 0;
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
    // A fresh mark value for mark(): vertices marked with it are "in the current set".
    uint32_t new_mark() {
        if (++mark_counter_ == 0) {  // wrapped: old marks could alias
            for (uint32_t v = 0; v < vertex_high_; ++v) slots_[v].mark = 0;
            mark_counter_ = 1;
        }
        return mark_counter_;
    }
    uint32_t& mark(uint32_t v) { return slots_[v].mark; }

    // The channels carried beside the buffer (attribute_store.hpp), or null for positions only.
    AttributeStore* attributes() const { return attributes_; }
    void set_attributes(AttributeStore* store) { attributes_ = store; }

    // Running counts for Stats.
    uint64_t vertices_merged() const { return vertices_merged_; }
    uint64_t nonmanifold_edges() const { return nonmanifold_edges_; }
    // Edges left without a partner when their vertices left P_in: true boundary (hole rims,
    // open borders, cracks between triangles that share no corner).
    uint64_t boundary_edges() const { return boundary_edges_; }
    size_t peak_vertices() const { return vertex_used_peak_; }

private:
    uint32_t weld(const float p[3], uint64_t hash);
    uint32_t alloc_vertex();
    void hash_erase(uint32_t v);
    void grow_hash();
    // The welding hash of a position: its float bits with −0 made +0 (exact welding), or its
    // weld grid cell, mixed.
    uint64_t weld_hash(const float p[3]) const {
        if (weld_eps_ == 0) {
            const uint64_t xy = uint64_t{float_key(p[0])} | uint64_t{float_key(p[1])} << 32;
            uint64_t h = xy * 0x9e3779b97f4a7c15ull ^ uint64_t { float_key(p[2]) } * 0xc2b2ae3d27d4eb4full;
            h ^= h >> 32;
            h *= 0xd6e8feb86659fd93ull;
            return h ^ (h >> 32);
        }
        return cell_hash(p);
    }
    uint64_t cell_hash(const float p[3]) const;
    // A float's bits, −0 as +0 (so that they weld).
    static uint32_t float_key(float x) {
        const uint32_t bits = std::bit_cast<uint32_t>(x);
        return (bits << 1) == 0 ? 0 : bits;
    }
    bool same_key(const float a[3], const float b[3]) const;
    double weld_cell(float x) const;  // grid index (an integral double) of a coordinate
    bool take_written_stub(uint32_t a, uint32_t b);
    bool one_fan(uint32_t v) const;
    // True when every fan round v is open: the faces reached from each open edge into v,
    // walking round v, are all of v's faces.
    bool open_fans(uint32_t v) const;
    void enter_interior(uint32_t f);

    size_t face_capacity_, vertex_capacity_;
    double weld_eps_;
    bool origin_set_ = false;
    double origin_[3] = {0, 0, 0};

    // Everything about one vertex, in one 128-byte pair of cache lines.
    struct alignas(128) VertexSlot {
        Vertex vertex;
        uint32_t mark;
        float partner_z;  // with Vertex::partner_xy
        Quadric quadric;
    };
    static_assert(sizeof(VertexSlot) == 128);

    void link_corner(uint32_t v, uint32_t c);
    void unlink_corner(uint32_t v, uint32_t c);

    RawArray<Face> faces_;
    RawArray<uint32_t> free_faces_;
    size_t free_face_count_ = 0, face_count_ = 0, pinned_face_count_ = 0;
    uint32_t face_high_ = 0, born_counter_ = 0;

    // Faces in the order they left P_in: a ring of (face, born) compacted when full (entries
    // of removed faces are dropped then).
    struct InteriorEntry {
        uint32_t face, born;
    };
    RawArray<InteriorEntry> interior_;
    size_t interior_mask_, interior_head_ = 0, interior_size_ = 0;  // capacity a power of two

    RawArray<VertexSlot> slots_;
    RawArray<uint32_t> free_vertices_;
    size_t free_vertex_stack_ = 0;
    uint32_t vertex_high_ = 0;
    size_t vertex_used_ = 0, vertex_used_peak_ = 0;
    uint32_t mark_counter_ = 0;
    RawArray<uint32_t> pending_;
    size_t pending_count_ = 0;
    bool pending_overflow_ = false;

    // Vertex index or kNoIndex; linear probing. The table in use is the first hash_mask_ + 1
    // slots, doubled (rehashing through hash_scratch_) when half full: P_in is usually a small
    // front, whose table then stays in cache, but may grow to every in-core vertex.
    RawArray<uint32_t> hash_;
    RawArray<uint32_t> hash_scratch_;
    size_t hash_mask_, hash_max_slots_, hash_count_ = 0;

    struct Stub {
        uint32_t a, gen_a, b, gen_b;
    };
    RawArray<Stub> stubs_;  // a == kNoIndex: empty; linear probing
    size_t stub_mask_, stub_count_ = 0;

    uint64_t vertices_merged_ = 0, nonmanifold_edges_ = 0, boundary_edges_ = 0;
    AttributeStore* attributes_ = nullptr;
    bool full_resolution_first_ = false;
};

}  // namespace meshstream::decimate
