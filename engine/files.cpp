// The job's files: see files.hpp.
#include "engine/files.hpp"

#include "io/error.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <vector>
#include <utility>

namespace meshstream::engine {

bool is_regular_file(const std::string& path) {
    struct stat st;
    return path != "-" && ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

namespace {

// Widens `box` by the finite coordinates of `xyz` (a NaN or inf coordinate decides nothing).
void add_corners(io::Bounds& box, std::span<const float> xyz) {
    for (size_t i = 0; i + 3 <= xyz.size(); i += 3)
        for (int a = 0; a < 3; ++a)
            if (std::isfinite(xyz[i + a])) {
                box.min[a] = std::min(box.min[a], xyz[i + a]);
                box.max[a] = std::max(box.max[a], xyz[i + a]);
            }
}

}  // namespace

io::Bounds input_bounds(const std::string& path, std::string_view from, const io::ReadOptions& options,
                        ProgressSink& progress) {
    return input_box(path, from, options, progress, false).box;
}

InputBox input_box(const std::string& path, std::string_view from, const io::ReadOptions& options,
                   ProgressSink& progress, bool vertices_will_do) {
    io::ReadOptions positions = options;  // nothing but positions is looked at
    positions.channels = io::ChannelKinds::none();
    positions.memory_budget_bytes = options.memory_budget_bytes / 8 * 7;  // beside the marks below
    io::Input in = io::open_input(path, from, positions);
    InputBox found;
    io::Bounds& box = found.box;
    box.min.fill(std::numeric_limits<float>::infinity());
    box.max.fill(-std::numeric_limits<float>::infinity());
    uint64_t done = 0;
    io::IndexedSource* own = in.reader->indexed();
    if (own != nullptr) found.vertex_table_bytes = own->vertex_table_bytes();
    // Every vertex, in order: no face is read.
    if (own != nullptr && vertices_will_do) {
        found.of_vertices = true;
        progress.phase("bounding box of the vertices", own->vertex_count());
        std::vector<float> xyz;
        for (uint64_t v = 0; v < own->vertex_count();) {
            const uint64_t n = std::min<uint64_t>(own->vertex_count() - v, 1 << 16);
            xyz.resize(3 * n);
            own->positions(v, n, xyz.data());
            add_corners(box, xyz);
            progress.update(v += n);
            if (progress.cancelled()) throw Cancelled();
        }
        return found;
    }
    progress.phase("bounding box", in.reader->triangle_count());
    // A file of vertices and faces (PLY) whose vertices' marks fit in an eighth of the budget:
    // the faces' indices mark the vertices used, then the vertices are read in order, which is
    // much cheaper than a triangle's corners looked up one by one. The same corners, the same box.
    if (own != nullptr && (own->vertex_count() + 7) / 8 <= options.memory_budget_bytes / 8) {
        std::vector<uint64_t> used((own->vertex_count() + 63) / 64);
        std::vector<uint32_t> indices;
        while (own->next_triangles(indices, io::TriangleChunk::kDefaultCapacity)) {
            for (uint32_t v : indices) used[v / 64] |= uint64_t{1} << (v % 64);
            progress.update(done += indices.size() / 3, in.source->stored_offset(), in.source->stored_size());
            if (progress.cancelled()) throw Cancelled();
            indices.clear();
        }
        for (uint64_t v = 0; v < own->vertex_count(); ++v)
            if (used[v / 64] >> (v % 64) & 1) {
                float xyz[3];
                own->vertex(v, xyz, nullptr);
                add_corners(box, xyz);
            }
        return found;
    }
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity);
    while (in.reader->next(chunk)) {
        add_corners(box, chunk.xyz());
        progress.update(done += chunk.size(), in.source->stored_offset(), in.source->stored_size());
        if (progress.cancelled()) throw Cancelled();
    }
    return found;
}

int longest_axis(const io::Bounds& box) {
    int best = 2;
    double best_extent = 0;
    for (int a = 0; a < 3; ++a) {
        const double extent = double(box.max[a]) - double(box.min[a]);
        if (extent > best_extent) {
            best_extent = extent;
            best = a;
        }
    }
    return best;
}

namespace {

// The file a path names, by device and inode, when it is an existing regular file ("-" is
// the descriptor: stdin for an input, stdout for an output). Symbolic links are followed.
std::optional<std::pair<dev_t, ino_t>> regular_file_id(const std::string& path, bool output) {
    struct stat st;
    const int rc = path == "-" ? ::fstat(output ? 1 : 0, &st) : ::stat(path.c_str(), &st);
    if (rc != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
    return std::pair{st.st_dev, st.st_ino};
}

std::string shown(const std::string& path, bool output) { return path != "-" ? path : output ? "<stdout>" : "<stdin>"; }

}  // namespace

const io::Format& output_format(const std::string& output, const std::string& format_name) {
    if (!format_name.empty()) {
        const io::Format* f = io::find_format(format_name);
        if (f == nullptr || f->open_writer == nullptr)
            throw io::OptionError(io::Setting::kTo, "unknown output format '" + format_name +
                                                        "' (one of: " + io::format_names(true) + ")");
        return *f;
    }
    if (const io::Format* f = io::format_for_extension(output, true)) return *f;
    throw io::OptionError(io::Setting::kTo, shown(output, true) +
                                                ": cannot tell the output format from the name (give its format, "
                                                "one of: " +
                                                io::format_names(true) + ")");
}

InputFiles input_files(const std::string& path, const io::MeshHeader& header) { return {path, header.side_files}; }

void refuse_output_over_inputs(const std::string& output, const std::vector<std::string>& output_side_files,
                               const std::vector<InputFiles>& inputs) {
    struct Target {
        std::string path;
        bool side;
    };
    std::vector<Target> targets{{output, false}};
    for (const std::string& side : output_side_files) targets.push_back({side, true});
    for (const Target& target : targets) {
        const auto id = regular_file_id(target.path, true);
        if (!id) continue;
        for (const InputFiles& in : inputs) {
            std::string why;
            if (regular_file_id(in.path, false) == id) why = "the input " + shown(in.path, false);
            for (const std::string& side : in.side_files)
                if (why.empty() && regular_file_id(side, false) == id)
                    why = side + ", which the input " + shown(in.path, false) + " reads";
            if (why.empty()) continue;
            const bool same_name = !target.side && target.path == in.path;
            throw io::OptionError(io::Setting::kOutput,
                                  shown(output, true) + ": " +
                                      (target.side ? "its side file " + target.path + " would overwrite " + why
                                                   : std::string("would overwrite ") + why +
                                                         (same_name ? "" : " (the same file, through a link)")) +
                                      "; write the output to another file");
        }
    }
}

void refuse_output_over_inputs(const std::string& output, const io::Format& format, const io::WriteOptions& options,
                               const std::vector<InputFiles>& inputs) {
    refuse_output_over_inputs(
        output, format.side_files ? format.side_files(output, options) : std::vector<std::string>{}, inputs);
}

}  // namespace meshstream::engine
