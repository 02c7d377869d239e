// How the commands use the read loop's triangle policy (io/triangle_input.hpp): which policy
// each command takes from its flags, and the counted warnings for what it dropped.
//   - convert, sort: every triangle is kept (lossless); --clean drops non-finite and
//     degenerate ones and counts them;
//   - decimate: drops them (it cannot use them) and counts them; --strict makes the first
//     one an error;
//   - info, compare: measure the file as it is; --strict makes the first one an error.
#pragma once

#include "io/triangle_input.hpp"
#include "tools/common.hpp"

namespace meshstream::tools {

enum class Command : uint8_t { kConvert, kSort, kDecimate, kMeasure };

// The policy for a command: `clean` is --clean (convert, sort), `strict` is --strict.
io::BadTriangles bad_triangle_policy(Command command, bool clean, bool strict);

// Opens `path` as ReadFlags say and wraps it in the read loop with the command's policy.
io::TriangleInput open_triangle_input(const std::string& path, const ReadFlags& read, Command command,
                                      bool clean = false);
// The same with the reader's options given (a command that splits --memory).
io::TriangleInput open_triangle_input(const std::string& path, const ReadFlags& read, const io::ReadOptions& options,
                                      Command command, bool clean = false);

// The warnings about the triangles a finished read loop dropped (engine/warnings.hpp).
using engine::dropped_triangles;
using engine::DroppedTriangles;
using engine::note_dropped_triangles;

// --clean for convert and sort.
void add_clean_flag(CLI::App* cmd, bool& clean);

}  // namespace meshstream::tools
