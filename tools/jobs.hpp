// The subcommands' jobs as calls: each takes the options as the command parses them and
// returns the object that --json prints, so the command and the Python module (python/) run
// the same code and report the same figures in the same words. A job draws the command's
// progress bar unless it is given a ProgressSink of its own; with `json` set it prints no text
// report (the summary, the figures of info and compare), only the warnings on stderr (unless
// Global::silent). Throws what the libraries throw (io/error.hpp), and UsageError for options
// that do not go together.
#pragma once

#include "decimate/stream_decimator.hpp"
#include "engine/progress.hpp"
#if MESHSTREAM_WITH_GLTF
#include "engine/tiles.hpp"
#endif
#include "tools/common.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace meshstream::engine {
class RangeProcesses;
}

namespace meshstream::tools {

struct ConvertOptions {
    std::string input, output;
    bool clean = false;
    bool json = false;
    unsigned threads = every_core();
    ReadFlags read;
    WriteFlags write;
};
// The options of `meshstream convert` registered on `app`, bound to `opt` (add_convert adds
// the callback that runs the job): the command line parses them, and the Python module checks
// its keyword arguments with the same options (python/meshstream_module.cpp). Likewise below.
CLI::App* convert_command(CLI::App& app, ConvertOptions& opt);
// The --json object of convert (tools/run_report.hpp).
nlohmann::ordered_json convert_job(const ConvertOptions& opt, engine::ProgressSink* progress = nullptr);

// sort's options: convert's and these.
struct SortOptions : ConvertOptions {
    std::string axis = "auto";  // x, y, z or auto
    bool stats = false;         // --stats' line on stderr
};
CLI::App* sort_command(CLI::App& app, SortOptions& opt);
nlohmann::ordered_json sort_job(const SortOptions& opt, engine::ProgressSink* progress = nullptr);

struct DecimateOptions {
    std::string input, output;
    std::optional<double> ratio;
    std::optional<uint64_t> target;
    size_t buffer = decimate::kDefaultBufferTriangles;
    uint64_t seed = 1;
    std::string weld;  // "" / "0.001" / "0.01%"
    std::optional<int> sorted_axis;
    std::string sort = "auto";  // --sort auto|always|never
    unsigned threads = every_core();
    bool threads_given = false;      // --threads given (else every core)
    std::string part;                // --part k/K
    std::vector<std::string> merge;  // --merge PART ... (the merge job, --part K/K)
    std::string weights;             // --weights normal=W,color=W,uv=W,NAME=W
    bool report = false;
    bool json = false;
    ReadFlags read;
    WriteFlags write;
};
CLI::App* decimate_command(CLI::App& app, DecimateOptions& opt, engine::RangeProcesses* processes = nullptr);
// `processes`: meshstream-mpi's; a process other than the first returns null.
nlohmann::ordered_json decimate_job(const DecimateOptions& opt, engine::RangeProcesses* processes = nullptr,
                                    engine::ProgressSink* progress = nullptr);

struct InfoOptions {
    std::string input;
    bool json = false;
    bool topology = false;                                // --topology: vertex and edge counts (compare/topology.hpp)
    bool order = false;                                   // --order: measure the stream's width (compare/order.hpp)
    uint64_t buffer = decimate::kDefaultBufferTriangles;  // --buffer: decimation buffer to judge against the width
    double ratio = 0.1;                                   // --ratio: the decimation ratio it is judged for
    ReadFlags read;
};
CLI::App* info_command(CLI::App& app, InfoOptions& opt);
// info's --json object (null without `json`: the text is printed instead).
nlohmann::ordered_json info_job(const InfoOptions& opt, engine::ProgressSink* progress = nullptr);

struct CompareCliOptions {
    std::string a, b;
    std::optional<uint64_t> samples;
    uint64_t seed = 1;
    bool json = false;
    bool attributes = false;
    ReadFlags read;
};
CLI::App* compare_command(CLI::App& app, CompareCliOptions& opt);
// compare's --json object (null without `json`: the text is printed instead). A sink's
// cancelled() is looked at between the comparison's progress steps.
nlohmann::ordered_json compare_job(const CompareCliOptions& opt, engine::ProgressSink* progress = nullptr);

#if MESHSTREAM_WITH_GLTF
struct TilesOptions {
    std::string input, output;  // the mesh, the tileset's directory
    uint64_t tile_triangles = engine::kDefaultTileTriangles;
    std::string compress = "meshopt";
    std::string origin;  // "LON,LAT,HEIGHT" or empty
    bool overwrite = false;
    bool json = false;
    unsigned threads = every_core();
    uint64_t seed = 1;
    ReadFlags read;
};
CLI::App* tiles_command(CLI::App& app, TilesOptions& opt);
// tiles' --json object (null without `json`: a line on stderr instead). Without a `progress`
// sink (the command) Ctrl-C, SIGTERM and SIGHUP cancel the build, which removes what it made,
// and then end the process as the signal would have; a sink's cancelled() does the same
// without the signal (engine::Cancelled is thrown).
nlohmann::ordered_json tiles_job(const TilesOptions& opt, engine::ProgressSink* progress = nullptr);
#endif

// Sets `cmd`'s callback: runs `job` on the parsed options and prints its report with --json
// (`indent` as nlohmann's dump(): -1 one line, as convert, sort and decimate print it).
template <class Options, class Job>
void run_when_parsed(CLI::App* cmd, std::shared_ptr<Options> opt, Job job, int indent = -1) {
    cmd->callback([opt, job, indent] {
        const nlohmann::ordered_json report = job(*opt);
        if (opt->json && !report.is_null()) std::printf("%s\n", report.dump(indent).c_str());
    });
}

}  // namespace meshstream::tools
