// `meshstream info FILE`: format, counts, bounding box, file size, degenerate triangles, the
// channels the file carries (normals, colours, texture coordinates, named scalars, materials)
// and what the reader skipped or repaired, in one streaming pass (memory: one chunk of
// positions; attribute values are not read), as plain text or --json.
#include "compare/order.hpp"
#include "compare/topology.hpp"
#include "decimate/stream_decimator.hpp"
#include "io/error.hpp"
#include "tools/cli_checks.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
#include "tools/jobs.hpp"
#if MESHSTREAM_WITH_GLTF
#include "engine/tiles.hpp"
#endif
#include "tools/order_text.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

namespace meshstream::tools {
namespace {

using compare::BufferVerdict;
using compare::OrderMeter;
using compare::OrderReport;
using compare::TopologyCounter;
using compare::TopologyReport;

struct InfoStats {
    uint64_t triangles = 0;
    uint64_t degenerate = 0;  // zero area (collinear or repeated corners)
    uint64_t non_finite = 0;  // a NaN or infinite coordinate
    float min[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                    std::numeric_limits<float>::infinity()};
    float max[3] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()};
};

void accumulate(const io::TriangleChunk& chunk, InfoStats& s) {
    auto xyz = chunk.xyz();
    for (size_t t = 0; t < chunk.size(); ++t) {
        const float* p = &xyz[9 * t];
        bool finite = true;
        for (int k = 0; k < 9; ++k) finite &= std::isfinite(p[k]);
        if (!finite) {
            ++s.non_finite;
            continue;
        }
        for (int v = 0; v < 3; ++v)
            for (int a = 0; a < 3; ++a) {
                s.min[a] = std::min(s.min[a], p[3 * v + a]);
                s.max[a] = std::max(s.max[a], p[3 * v + a]);
            }
        // Exact zero-area test in double: the cross product of two edges vanishes.
        double e1[3], e2[3];
        for (int a = 0; a < 3; ++a) {
            e1[a] = double(p[3 + a]) - p[a];
            e2[a] = double(p[6 + a]) - p[a];
        }
        double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
               cz = e1[0] * e2[1] - e1[1] * e2[0];
        if (cx == 0 && cy == 0 && cz == 0) ++s.degenerate;
    }
    s.triangles += chunk.size();
}

// "uchar RGBA", "float RGB".
std::string color_text(const io::ColorFormat& c) {
    return std::string(io::scalar_type_name(c.type)) + (c.alpha ? " RGBA" : " RGB");
}

// "uchar red, int label".
std::string scalars_text(const std::vector<io::ScalarChannel>& list) {
    std::string out;
    for (const io::ScalarChannel& s : list) {
        if (!out.empty()) out += ", ";
        out += std::string(io::scalar_type_name(s.type)) + " " + io::printable(s.name, 64);
    }
    return out;
}

nlohmann::ordered_json scalars_json(const std::vector<io::ScalarChannel>& list) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const io::ScalarChannel& s : list) out.push_back({{"name", s.name}, {"type", io::scalar_type_name(s.type)}});
    return out;
}

// The channels a file carries, per corner and per triangle.
nlohmann::ordered_json channels_json(const io::Channels& c) {
    nlohmann::ordered_json j = nlohmann::ordered_json::object();
    if (c.normal) j["normal"] = {{"type", "float"}, {"components", 3}};
    if (c.color) j["color"] = {{"type", io::scalar_type_name(c.color->type)}, {"components", c.color->alpha ? 4 : 3}};
    if (c.uv_sets > 0) j["uv"] = {{"sets", c.uv_sets}, {"type", "float"}, {"components", 2}};
    if (!c.vertex_scalars.empty()) j["vertex_scalars"] = scalars_json(c.vertex_scalars);
    if (c.vertex_id) j["vertex_id"] = true;
    if (c.material) j["material"] = {{"type", "uint"}, {"components", 1}};
    if (!c.face_scalars.empty()) j["face_scalars"] = scalars_json(c.face_scalars);
    return j;
}

std::string color_values(const std::array<float, 4>& rgba) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.6g %.6g %.6g %.6g", rgba[0], rgba[1], rgba[2], rgba[3]);
    return buf;
}

}  // namespace

#if MESHSTREAM_WITH_GLTF
namespace {

// A 3D Tiles tileset (`meshstream tiles`' tileset.json): its levels instead of a mesh's figures.
bool names_a_tileset(const std::string& path) {
    return path.size() > 5 && path.compare(path.size() - 5, 5, ".json") == 0 && is_regular_file(path);
}

nlohmann::ordered_json tileset_info(const InfoOptions& opt) {
    const engine::TilesetSummary t = engine::summarize_tileset(opt.input);
    if (opt.json) {
        nlohmann::ordered_json levels = nlohmann::ordered_json::array();
        for (const engine::TileLevel& l : t.levels)
            levels.push_back({{"depth", l.depth}, {"tiles", l.tiles}, {"leaves", l.leaves}, {"triangles", l.triangles},
                              {"bytes", l.bytes}, {"min_error", l.min_error}, {"max_error", l.max_error}});
        return {{"file", opt.input}, {"format", "3d-tiles"}, {"version", t.version}, {"placed", t.placed},
                {"geometric_error", t.geometric_error}, {"depth", t.levels.size()}, {"tiles", t.tiles},
                {"triangles", t.triangles}, {"bytes", t.bytes}, {"json_files", t.json_files}, {"levels", levels}};
    }
    std::printf("file:        %s\n", opt.input.c_str());
    std::printf("format:      3D Tiles %s tileset%s\n", t.version.c_str(), t.placed ? " (placed on the globe)" : "");
    std::printf("depth:       %zu levels, %llu tiles, %s triangles, %s in %llu JSON file(s) and the tiles\n",
                t.levels.size(), static_cast<unsigned long long>(t.tiles), human_count(double(t.triangles)).c_str(),
                human_bytes(double(t.bytes)).c_str(), static_cast<unsigned long long>(t.json_files));
    std::printf("error:       %.6g (the tileset's geometricError)\n", t.geometric_error);
    for (const engine::TileLevel& l : t.levels)
        std::printf("  depth %-3d %6llu tiles (%llu leaves) %12s triangles %10s  error %.6g..%.6g\n", l.depth,
                    static_cast<unsigned long long>(l.tiles), static_cast<unsigned long long>(l.leaves),
                    human_count(double(l.triangles)).c_str(), human_bytes(double(l.bytes)).c_str(), l.min_error,
                    l.max_error);
    return nullptr;
}

}  // namespace
#endif

nlohmann::ordered_json info_job(const InfoOptions& opt, engine::ProgressSink* progress) {
#if MESHSTREAM_WITH_GLTF
    if (names_a_tileset(opt.input)) return tileset_info(opt);
#endif
    // info reports bad triangles; --strict makes the first one an error instead. It looks at
    // positions (and vertex ids, for --topology) only: the reader stores no attribute values,
    // and the header still lists every channel.
    io::ReadOptions read = opt.read.options();
    read.channels = io::ChannelKinds::none();
    io::TriangleInput in = open_triangle_input(opt.input, opt.read, read, Command::kMeasure);
    const io::MeshHeader& header = in.header();
    // What info prints must not land in the file it reads (`info scan.stl >> scan.stl`).
    refuse_output_over_inputs("-", {}, {input_files(opt.input, header)});
    InfoStats stats;
    io::Channels positions;
    positions.vertex_id = header.channels.vertex_id;
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, positions);
    std::unique_ptr<TopologyCounter> topology;
    if (opt.topology)
        topology = std::make_unique<TopologyCounter>(opt.read.options().memory_budget_bytes, opt.read.tmpdir);
    std::optional<OrderMeter> meter;
    if (opt.order) meter.emplace(opt.read.options().memory_budget_bytes);
    {
        std::optional<Progress> bar;
        if (progress)
            progress->phase("reading", header.triangle_count);
        else
            bar.emplace("reading", header.triangle_count);
        engine::ProgressSink& sink = progress ? *progress : *bar;
        while (in.next(chunk)) {
            accumulate(chunk, stats);
            if (topology) topology->add(chunk);
            if (meter) meter->add(chunk);
            sink.update(stats.triangles, in.source().stored_offset(), in.source().stored_size());
            engine::throw_if_cancelled(sink);
        }
    }
    // The size on disk (compressed for gzip input, whose decoded size is reported beside it).
    std::error_code size_error;
    const uint64_t file_size = opt.input == "-" ? 0 : std::filesystem::file_size(opt.input, size_error);
    const bool has_file_size = opt.input != "-" && !size_error;
    uint64_t decoded_bytes = in.source().offset();
    bool has_box = stats.triangles > stats.non_finite;
    static const char* kAxes[] = {"x", "y", "z"};

    if (opt.json) {
        nlohmann::ordered_json j;
        j["file"] = opt.input;
        j["format"] = std::string(in.format().name);
        if (!header.variant.empty()) j["variant"] = header.variant;
        j["gzip"] = in.source().gzip();
        if (has_file_size) j["file_bytes"] = file_size;
        if (in.source().gzip()) j["decoded_bytes"] = decoded_bytes;
        j["triangles"] = stats.triangles;
        if (header.vertex_count) j["vertices"] = *header.vertex_count;
        j["degenerate_triangles"] = stats.degenerate;
        j["non_finite_triangles"] = stats.non_finite;
        if (has_box) {
            j["bbox_min"] = {stats.min[0], stats.min[1], stats.min[2]};
            j["bbox_max"] = {stats.max[0], stats.max[1], stats.max[2]};
        } else {
            j["bbox_min"] = nullptr;
            j["bbox_max"] = nullptr;
        }
        if (header.sorted_axis) j["sorted_axis"] = kAxes[*header.sorted_axis];
        j["channels"] = channels_json(header.channels);
        if (!header.materials.empty()) {
            auto& list = j["materials"] = nlohmann::ordered_json::array();
            for (const io::Material& m : header.materials) {
                nlohmann::ordered_json e = {
                    {"name", m.name},
                    {"base_color", {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]}}};
                if (m.texture)
                    e["texture"] = {{"uri", m.texture->uri},
                                    {"mime_type", m.texture->mime_type},
                                    {"bytes", m.texture->bytes.size()}};
                list.push_back(e);
            }
        }
        for (const auto& [k, v] : header.notes) j["notes"][k] = io::render(v, flag_name);
        if (!header.warnings.empty()) {
            auto& list = j["warnings"] = nlohmann::ordered_json::array();
            for (const io::ReaderWarning& w : header.warnings) {
                nlohmann::ordered_json e = {{"text", io::render(w.text, flag_name)}, {"count", w.count}};
                if (w.first_line != 0) e["line"] = w.first_line;
                if (w.first_byte_offset != io::Error::kNoOffset) e["byte"] = w.first_byte_offset;
                list.push_back(e);
            }
        }
        if (topology) {
            TopologyReport t = topology->finish();
            j["topology"] = {{"welded_by", t.by_vertex_id ? "vertex id" : "position"},
                             {"vertices", t.vertices},
                             {"edges", t.edges},
                             {"boundary_edges", t.boundary_edges},
                             {"non_manifold_edges", t.non_manifold_edges}};
        }
        if (meter) {
            OrderReport r = meter->finish();
            BufferVerdict v = buffer_verdict(r, opt.buffer, opt.ratio);
            auto& o = j["order"];
            o["width"] = r.width;
            o["width_error"] = r.width_error;
            o["exact"] = r.exact();
            o["sample_rate"] = r.sample_rate;
            o["width_at"] = r.width_at;
            o["buffer"] = opt.buffer;
            o["ratio"] = opt.ratio;
            o["buffer_needed"] = buffer_needed(r, opt.ratio);
            o["buffer_suffices"] = v == BufferVerdict::kSuffices   ? nlohmann::json(true)
                                   : v == BufferVerdict::kTooSmall ? nlohmann::json(false)
                                                                   : nlohmann::json(nullptr);
            o["key_descents"] = {{"x", r.descents[0]}, {"y", r.descents[1]}, {"z", r.descents[2]}};
        }
        return j;
    }
    std::printf("file:        %s\n", opt.input.c_str());
    std::printf("format:      %s%s%s%s\n", std::string(in.format().name).c_str(), header.variant.empty() ? "" : " (",
                header.variant.c_str(), header.variant.empty() ? "" : ")");
    if (in.source().gzip()) std::printf("compression: gzip (%llu bytes decoded)\n", (unsigned long long)decoded_bytes);
    if (has_file_size) std::printf("file size:   %llu bytes\n", (unsigned long long)file_size);
    std::printf("triangles:   %llu\n", (unsigned long long)stats.triangles);
    if (header.vertex_count) std::printf("vertices:    %llu\n", (unsigned long long)*header.vertex_count);
    std::printf("degenerate:  %llu (zero area)\n", (unsigned long long)stats.degenerate);
    if (stats.non_finite)
        std::printf("non-finite:  %llu (NaN or infinite coordinates)\n", (unsigned long long)stats.non_finite);
    if (has_box) {
        std::printf("bbox min:    %.9g %.9g %.9g\n", stats.min[0], stats.min[1], stats.min[2]);
        std::printf("bbox max:    %.9g %.9g %.9g\n", stats.max[0], stats.max[1], stats.max[2]);
    } else {
        std::printf("bbox:        empty\n");
    }
    if (header.sorted_axis) std::printf("sorted along: %s\n", kAxes[*header.sorted_axis]);
    const io::Channels& c = header.channels;
    std::string channels;
    auto add = [&](const std::string& item) { channels += (channels.empty() ? "" : ", ") + item; };
    if (c.normal) add("normal (3 × float)");
    if (c.color) add("colour (" + color_text(*c.color) + ")");
    if (c.uv_sets > 0)
        add("texture coordinates (" + std::to_string(c.uv_sets) + (c.uv_sets == 1 ? " set" : " sets") +
            " of 2 × float)");
    if (!c.vertex_scalars.empty())
        add(std::to_string(c.vertex_scalars.size()) + " vertex scalar" + (c.vertex_scalars.size() == 1 ? "" : "s"));
    if (c.material) add("material index");
    if (!c.face_scalars.empty())
        add(std::to_string(c.face_scalars.size()) + " face scalar" + (c.face_scalars.size() == 1 ? "" : "s"));
    std::printf("channels:    %s\n", channels.empty() ? "positions only" : channels.c_str());
    if (!c.vertex_scalars.empty()) std::printf("vertex scalars: %s\n", scalars_text(c.vertex_scalars).c_str());
    if (!c.face_scalars.empty()) std::printf("face scalars: %s\n", scalars_text(c.face_scalars).c_str());
    if (!header.materials.empty()) {
        std::printf("materials:   %zu\n", header.materials.size());
        for (size_t i = 0; i < header.materials.size(); ++i) {
            const io::Material& m = header.materials[i];
            std::string line = "  " + std::to_string(i) + ": '" + io::printable(m.name, 64) + "', base colour " +
                               color_values(m.base_color);
            if (m.texture)
                line += ", texture '" + io::printable(m.texture->uri, 200) + "'" +
                        (m.texture->mime_type.empty() ? "" : " (" + m.texture->mime_type + ")") + ", " +
                        (m.texture->bytes.empty() ? std::string("not loaded")
                                                  : std::to_string(m.texture->bytes.size()) + " bytes");
            std::printf("%s\n", line.c_str());
        }
    }
    for (const auto& [k, v] : header.notes)
        std::printf("%-12s %s\n", (k + ":").c_str(), io::render(v, flag_name).c_str());
    for (const io::ReaderWarning& w : header.warnings) {
        std::printf("warning:     %s%s (%llu)\n", io::render(w.text, flag_name).c_str(),
                    io::warning_position(w).c_str(), (unsigned long long)w.count);
    }
    if (topology) {
        TopologyReport t = topology->finish();
        std::printf("topology:    %llu vertices (welded by %s), %llu edges, %llu boundary, %llu non-manifold\n",
                    (unsigned long long)t.vertices, t.by_vertex_id ? "vertex id" : "position",
                    (unsigned long long)t.edges, (unsigned long long)t.boundary_edges,
                    (unsigned long long)t.non_manifold_edges);
    }
    if (meter) std::printf("%s", format_order_text(meter->finish(), opt.buffer, opt.ratio, header.sorted_axis).c_str());
    return nullptr;
}

CLI::App* info_command(CLI::App& app, InfoOptions& options) {
    InfoOptions* opt = &options;
    CLI::App* cmd = app.add_subcommand("info",
                                       "format, counts, bounding box, degenerate triangles, channels, order\n"
                                       "FILE: a mesh file, '-' for stdin; gzip is detected");
    cmd->add_option("FILE", opt->input, "mesh file ('-' = stdin)")->required();
    cmd->add_flag("--json", opt->json, "print JSON instead of text");
    cmd->add_flag("--topology", opt->topology,
                  "count vertices, boundary and non-manifold edges\n"
                  "Welded by vertex id for PLY/OBJ, else by position; sorts 144 bytes a triangle within --memory, "
                  "spilling beyond");
    cmd->add_flag("--order", opt->order,
                  "measure how far the file is from the order decimate needs\n"
                  "The stream's width: triangles held at once until all their vertices' uses were read (exact "
                  "within --memory, else sampled; see docs/cli.md)");
    // The same ranges as decimate's: settings it cannot run are not judged.
    cmd->add_option("--buffer", opt->buffer, "with --order: the decimate --buffer to judge (default " +
                                                  std::to_string(decimate::kDefaultBufferTriangles) + ")")
        ->type_name("N")
        ->check(CLI::Range(size_t{16}, size_t{1} << 29));
    cmd->add_option("--ratio", opt->ratio,
                    "with --order: the decimation ratio to judge it for (default 0.1)\n"
                    "The buffer needed grows with it")
        ->type_name("P")
        ->check(open_unit_interval());
    add_read_flags(cmd, opt->read);
    strict_reports_bad_triangles(cmd);
    cmd->footer("  meshstream info scan.ply --order");
    return cmd;
}

void add_info(CLI::App& app) {
    auto opt = std::make_shared<InfoOptions>();
    run_when_parsed(
        info_command(app, *opt), opt, [](InfoOptions& o) { return info_job(o); }, 2);
}

}  // namespace meshstream::tools
