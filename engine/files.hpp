// The files a job reads and writes, as the engine looks at them before any work: whether an
// input can be read twice, its bounding box, and an output that would overwrite an input.
#pragma once

#include "engine/progress.hpp"
#include "io/format.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace meshstream::engine {

// True for an existing regular file (not "-", a pipe or a device): one that can be read twice.
bool is_regular_file(const std::string& path);

// The input's bounding box, the box of its triangles' corners, from a pass over the file (finite
// coordinates only; reported to `progress` as the phase "bounding box").
// An input without finite coordinates gives min = +inf, max = -inf. Throws io::Error like
// io::open_input. Memory: within options.memory_budget_bytes (the reader's tables 7/8 of it; a
// PLY's marks of the vertices its faces use, a bit a vertex, the rest when they fit there).
io::Bounds input_bounds(const std::string& path, std::string_view from, const io::ReadOptions& options,
                        ProgressSink& progress);

// input_bounds's box, or, for `vertices_will_do` and an input whose reader holds its vertices
// apart from its faces (PLY: io::IndexedSource), the box of all its vertices, used by a face or
// not, with `of_vertices` set: its vertices read in bulk, in order, without its faces. It contains the triangles' box, and is that box unless some vertex no
// face uses lies outside it; a caller that needs the triangles' own box checks it against the
// corners it reads later.
struct InputBox {
    io::Bounds box;
    bool of_vertices = false;
    uint64_t vertex_table_bytes = 0;  // io::IndexedSource::vertex_table_bytes; 0 for other formats
};
InputBox input_box(const std::string& path, std::string_view from, const io::ReadOptions& options,
                   ProgressSink& progress, bool vertices_will_do);
// The axis along which `box` is longest (z for an empty or flat box, the usual scan axis).
int longest_axis(const io::Bounds& box);

// The format an output is written in: the one named (a registry name), else the one of the
// output name's extension. Throws io::OptionError (the output format's setting) when neither
// names a writable format.
const io::Format& output_format(const std::string& output, const std::string& format_name);

// An input for refuse_output_over_inputs: its path ("-" = stdin) and the other files its
// reader read (MeshHeader::side_files).
struct InputFiles {
    std::string path;
    std::vector<std::string> side_files;
};
// The InputFiles of an opened input.
InputFiles input_files(const std::string& path, const io::MeshHeader& header);
// Refuses with io::OptionError (the output's setting), before anything is written, an output
// that would overwrite an input: the same regular file by device and inode (so also a symbolic
// or hard link to it, and stdout redirected into it), or a side file of either: one the output's
// format writes beside it (`output_side_files`, from Format::side_files) or one an input's reader
// read.
void refuse_output_over_inputs(const std::string& output, const std::vector<std::string>& output_side_files,
                               const std::vector<InputFiles>& inputs);
// The same with the side files `format` names for `output`.
void refuse_output_over_inputs(const std::string& output, const io::Format& format, const io::WriteOptions& options,
                               const std::vector<InputFiles>& inputs);

}  // namespace meshstream::engine
