// `meshstream tiles IN OUTDIR`: the command line of engine::tile_file (engine/tiles.hpp), which
// writes a mesh of any size as OGC 3D Tiles 1.1.
#include "engine/tiles.hpp"
#include "io/error.hpp"
#include "io/text_tokens.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/jobs.hpp"
#include "tools/run_report.hpp"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>

namespace meshstream::tools {
namespace {

// Ctrl-C and termination ask the engine to stop: it removes the tileset being built and its
// temporary files, then the signal ends the process as it would have.
std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};
extern "C" void ask_to_stop(int sig) {
    g_signal.store(sig);
    g_cancel.store(true);
}

class CancellableProgress final : public engine::ProgressSink {
public:
    explicit CancellableProgress(Progress& bar) : bar_(bar) {}
    void phase(std::string label, std::optional<uint64_t> total) override { bar_.phase(std::move(label), total); }
    void update(uint64_t done) override { bar_.update(done); }
    void update(uint64_t done, uint64_t bytes_read, std::optional<uint64_t> file_bytes) override {
        bar_.update(done, bytes_read, file_bytes);
    }
    void status(const std::string& text) override { bar_.status(text); }
    bool cancelled() const override { return g_cancel.load(); }

private:
    Progress& bar_;
};

engine::TileCompression parse_compression(const std::string& text) {
    if (text == "meshopt") return engine::TileCompression::kMeshopt;
    if (text == "draco") return engine::TileCompression::kDraco;
    if (text == "none") return engine::TileCompression::kNone;
    throw UsageError("--compress must be meshopt, draco or none, got '" + text + "'");
}

engine::GeoOrigin parse_origin(const std::string& text) {
    double v[3];
    size_t start = 0;
    for (int i = 0; i < 3; ++i) {
        const size_t comma = i < 2 ? text.find(',', start) : text.size();
        if (comma == std::string::npos || !io::parse_number(std::string_view(text).substr(start, comma - start), v[i]))
            throw UsageError("--origin must be LON,LAT,HEIGHT (degrees, degrees, metres), got '" + text + "'");
        start = comma + 1;
    }
    if (start <= text.size() && text.find(',', start) != std::string::npos)
        throw UsageError("--origin must be LON,LAT,HEIGHT (degrees, degrees, metres), got '" + text + "'");
    return {v[0], v[1], v[2]};
}

// The build, cancelled by the signals (no `sink`) or by the sink.
engine::TilesResult build(const engine::TilesSettings& s, engine::ProgressSink* sink) {
    if (sink) return engine::tile_file(s, *sink);
    g_cancel.store(false);
    g_signal.store(0);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, ask_to_stop);
    try {
        Progress bar("tiles", std::nullopt);
        CancellableProgress progress(bar);
        return engine::tile_file(s, progress);
    } catch (const engine::Cancelled&) {
        // Everything is removed: end as the signal would have.
        if (const int sig = g_signal.load(); sig != 0) {
            std::signal(sig, SIG_DFL);
            std::raise(sig);
        }
        throw;
    }
}

}  // namespace

nlohmann::ordered_json tiles_job(const TilesOptions& opt, engine::ProgressSink* progress) {
    const auto start = std::chrono::steady_clock::now();
    engine::TilesSettings s;
    s.input = opt.input;
    s.input_format = opt.read.from;
    s.outdir = opt.output;
    s.tile_triangles = opt.tile_triangles;
    s.compression = parse_compression(opt.compress);
    if (!opt.origin.empty()) s.origin = parse_origin(opt.origin);
    s.overwrite = opt.overwrite;
    s.threads = opt.threads;
    s.seed = opt.seed;
    s.read = opt.read.options();
    const engine::TilesResult result = build(s, progress);
    print_warnings(result.warnings);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!opt.json) {
        if (!global().quiet)
            std::fprintf(stderr, "%s: %zu levels, %llu tiles, %s (leaves %s) from %s triangles in %.1f s\n",
                         opt.output.c_str(), result.levels.size(), static_cast<unsigned long long>(result.tiles),
                         human_bytes(double(result.bytes)).c_str(), human_bytes(double(result.leaf_bytes)).c_str(),
                         human_count(double(result.triangles_in)).c_str(), seconds);
        return nullptr;
    }
    RunReport report;
    report.command = "tiles";
    report.inputs = {{opt.input, result.input_format, false}};
    report.outputs = {{opt.output + "/tileset.json", "3d-tiles", false}};
    report.triangles_in = result.triangles_in;
    for (const engine::TileLevel& l : result.levels) report.triangles_out += l.triangles;
    report.seconds = seconds;
    report.peak_rss_bytes = peak_rss_bytes();
    nlohmann::ordered_json levels = nlohmann::ordered_json::array();
    for (const engine::TileLevel& l : result.levels)
        levels.push_back({{"depth", l.depth}, {"tiles", l.tiles}, {"leaves", l.leaves}, {"triangles", l.triangles},
                          {"bytes", l.bytes}, {"min_error", l.min_error}, {"max_error", l.max_error}});
    report.details = {{"tile_triangles", opt.tile_triangles}, {"compress", opt.compress},
                      {"tiles", result.tiles}, {"bytes", result.bytes}, {"leaf_bytes", result.leaf_bytes},
                      {"json_files", result.json_files}, {"geometric_error", result.geometric_error}, {"levels", levels}};
    return run_report_json(report, result.warnings);
}

CLI::App* tiles_command(CLI::App& app, TilesOptions& opt) {
    CLI::App* cmd = app.add_subcommand(
        "tiles",
        "OGC 3D Tiles 1.1: level-of-detail GLB tiles and a tileset.json, built out of core\n"
        "  IN: any mesh ('-' = stdin, spooled); OUTDIR: a new or empty directory (--overwrite replaces one)");
    cmd->add_option("IN", opt.input, "input mesh ('-' = stdin)")->required();
    cmd->add_option("OUTDIR", opt.output, "the tileset's directory")->required();
    cmd->add_option("--tile-triangles", opt.tile_triangles, "at most N triangles a leaf, about N above (default 65536)")
        ->type_name("N")
        ->check(CLI::Range(uint64_t{256}, uint64_t{1} << 32));
    cmd->add_option("--compress", opt.compress, "the tiles' encoding: meshopt (default), draco or none")
        ->type_name("FMT")
        ->check(CLI::IsMember({"meshopt", "draco", "none"}));
    cmd->add_option("--origin", opt.origin, "put the model's origin there (WGS84 degrees, metres; z up)")
        ->type_name("LON,LAT,H");
    cmd->add_flag("--overwrite", opt.overwrite, "replace OUTDIR when it is not empty (once the new tileset is complete)");
    cmd->add_option("--seed", opt.seed, "random seed of the decimations and error samples (default 1)")
        ->type_name("N");
    add_json_flag(cmd, opt.json);
    add_threads_option(cmd, opt.threads, "decimate the levels on N cores");
    add_read_flags(cmd, opt.read);
    cmd->footer(
        "  meshstream tiles scan.ply web/scan\n"
        "  meshstream tiles scan.ply web/scan --origin 7.4474,46.9480,540 --compress draco\n"
        "  meshstream info web/scan/tileset.json");
    return cmd;
}

void add_tiles(CLI::App& app) {
    auto opt = std::make_shared<TilesOptions>();
    run_when_parsed(tiles_command(app, *opt), opt, [](TilesOptions& o) { return tiles_job(o); });
}

}  // namespace meshstream::tools
