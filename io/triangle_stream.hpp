// meshstream's triangle stream: a binary triangle soup that needs no count before its body,
// for pipes between meshstream commands (`meshstream sort big.stl - | meshstream decimate -
// out.glb`) and for temporary spools. It carries every channel of io::Channels and the
// material table, so nothing is lost between stages, and ends with a marker that repeats the
// count, so a cut stream is an error rather than a shorter mesh. Byte layout (all little
// endian): docs/formats.md, "meshstream triangle stream".
//
//   header:  magic 89 'M' 'S' 'H' 0D 0A 1A 0A, u32 version (1), u64 body bytes, body:
//            count (u64, ~0 unknown), sorted axis, channels, scalar names, material table
//   chunks:  u32 n (1 .. 2^24), then n fixed-size triangle records (positions, then each
//            channel the header names, in io::Channels order)
//   end:     u32 0, u64 triangle count, 'M' 'S' 'H' 'E'
//
// Memory class: streams (one record buffer of a chunk's size plus the 1 MiB read buffer); the
// header's material table, textures included, is held, and refused past --memory.
#pragma once

#include "io/format.hpp"

namespace meshstream::io {

extern const Format kTriangleStreamFormat;  // "stream" (extension .mstream)

// True when `head` begins with the stream's 8 magic bytes.
bool probe_triangle_stream(std::span<const std::byte> head);

}  // namespace meshstream::io
