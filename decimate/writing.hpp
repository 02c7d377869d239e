// WRITE (Wu & Kobbelt 2003, §4.4): the in-core face that left P_in first is written. At write
// time each vertex not yet written moves once to the minimum of its quadric and is then
// frozen, with a stable output id, so neighbouring triangles written later share it.
#pragma once

#include "decimate/attributes.hpp"
#include "decimate/emit.hpp"
#include "decimate/halfedge_buffer.hpp"
#include "io/chunk.hpp"

#include <cstdint>

namespace meshstream::decimate {

// Collects written triangles into a fixed chunk and hands it to an Emit when full.
class TriangleOutput {
public:
    // With `layout` (which must outlive this), chunks carry its channels too.
    explicit TriangleOutput(size_t chunk_triangles, const AttributeLayout* layout = nullptr);
    void emit(const float xyz[9], const uint64_t ids[3], const Emit& out);
    // The same with the channels: each corner's m values, the face's material and face scalars.
    void emit(const float xyz[9], const uint64_t ids[3], const Emit& out, const float* const corners[3],
              uint32_t material, const double* face_scalars);
    // Hands over the partial chunk, if any.
    void flush(const Emit& out);
    uint64_t triangle_count() const { return triangle_count_; }

private:
    io::TriangleChunk chunk_;
    const AttributeLayout* layout_;
    uint64_t triangle_count_ = 0;
};

// The face to write next: the one that left P_in first among those in core
// (HalfEdgeBuffer::oldest_interior_face), or kNoIndex when every in-core face touches P_in
// (the caller must then force a write or read no further). Wu & Kobbelt (§4.4) write the face
// of largest error among a few on P_out; on streaming input the faces that left P_in first lie
// on P_out or next to it, so P_out advances as one front behind the input, and they are the
// faces the greedy decimation has long finished with.
uint32_t pick_write(HalfEdgeBuffer& buffer);

// Moves vertex v to its quadric minimum when its quadric is complete (not on P_in, manifold,
// no open edge), the 3×3 system is well conditioned, the move stays within the longest
// incident edge and no incident face flips or degenerates. When the system is singular it
// takes instead the best, by v's quadric error, of the last collapsed edge's ends and its
// midpoint (v's own position, the far end p, (v+p)/2), under the same checks. Otherwise it
// keeps its position (an input position or a collapse target, both on the surface).
// Returns true when it moved.
bool place_vertex(HalfEdgeBuffer& buffer, uint32_t v);

// Writes face f: places and freezes its vertices (ids from `next_id`), emits it, marks its
// neighbours' edges as P_out and removes it from the buffer. Returns how many of its
// vertices moved to their quadric minimum.
int write_face(HalfEdgeBuffer& buffer, uint32_t f, uint64_t& next_id, TriangleOutput& output, const Emit& out);

// Passes a triangle whose corners welded together (degenerate) straight through: its
// vertices are frozen where they are (they are on P_in) and it is emitted as read.
// A passed triangle's own channels (with an attribute store): each corner's m values, material,
// face scalars.
struct PassedChannels {
    const float* corners[3];
    uint32_t material;
    const double* face_scalars;
};
void pass_through(HalfEdgeBuffer& buffer, const uint32_t vertex[3], uint64_t& next_id, TriangleOutput& output,
                  const Emit& out, const PassedChannels* channels = nullptr);

}  // namespace meshstream::decimate
