// The commands' triangle policies and their warnings: see input_filter.hpp.
#include "tools/input_filter.hpp"

namespace meshstream::tools {

io::BadTriangles bad_triangle_policy(Command command, bool clean, bool strict) {
    switch (command) {
        case Command::kConvert:
        case Command::kSort:
            // --strict is about what an output cannot hold; triangles asked to be dropped are
            // no such loss.
            return clean ? io::BadTriangles::kDrop : io::BadTriangles::kKeep;
        case Command::kDecimate: return strict ? io::BadTriangles::kRefuse : io::BadTriangles::kDrop;
        case Command::kMeasure: return strict ? io::BadTriangles::kRefuse : io::BadTriangles::kKeep;
    }
    return io::BadTriangles::kKeep;
}

io::TriangleInput open_triangle_input(const std::string& path, const ReadFlags& read, const io::ReadOptions& options,
                                      Command command, bool clean) {
    return io::TriangleInput(io::open_input(path, read.from, options),
                             bad_triangle_policy(command, clean, read.strict));
}

io::TriangleInput open_triangle_input(const std::string& path, const ReadFlags& read, Command command, bool clean) {
    return open_triangle_input(path, read, read.options(), command, clean);
}

void add_clean_flag(CLI::App* cmd, bool& clean) {
    cmd->add_flag("--clean", clean,
                  "drop NaN/inf and degenerate triangles (default: every triangle is kept)\n"
                  "Drops triangles with a NaN or infinite coordinate and degenerate ones (two corners at the same "
                  "position), and counts them in a warning");
}

}  // namespace meshstream::tools
