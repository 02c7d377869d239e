// --json for convert, decimate and sort: the one object each prints on stdout at the end,
// built from the run's statistics apart from the run itself, so its shape is tested without a
// mesh. Keys (docs/cli.md): command, inputs and outputs ({path, format, gzip}), triangles_in,
// triangles_out, seconds, triangles_per_second (input triangles), peak_rss_bytes, the
// command's own figures under its name, and warnings ({code, text, count}).
#pragma once

#include "tools/common.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace meshstream::tools {

struct RunFile {
    std::string path;    // as given ("-" = stdin/stdout)
    std::string format;  // the registry's name ("stl", "stl-ascii", "ply", ...)
    bool gzip = false;
};

struct RunReport {
    std::string command;  // "convert", "decimate", "sort"
    std::vector<RunFile> inputs, outputs;
    uint64_t triangles_in = 0;   // read from the inputs
    uint64_t triangles_out = 0;  // written
    double seconds = 0;          // wall time of the whole command
    uint64_t peak_rss_bytes = 0;
    // The command's own figures (decimate: ratio, target, forced writes...; sort: axis, runs).
    nlohmann::ordered_json details = nlohmann::ordered_json::object();
};

nlohmann::ordered_json run_report_json(const RunReport& report, const Warnings& warnings);

// The report of a job that read `input` and wrote `output`: formats, gzip and counts from its
// result (engine::ConvertResult, SortResult or DecimateResult), its time, and this process's
// peak RSS.
template <class Result>
RunReport run_report_of(std::string command, const std::string& input, const std::string& output, const Result& result,
                        double seconds) {
    RunReport report;
    report.command = std::move(command);
    report.inputs = {{input, result.input_format, result.input_gzip}};
    report.outputs = {{output, result.output_format, result.output_gzip}};
    report.triangles_in = result.triangles_in;
    report.triangles_out = result.triangles_out;
    report.seconds = seconds;
    report.peak_rss_bytes = peak_rss_bytes();
    return report;
}

// --json on a writing command; its help says that stdout then holds the object only.
void add_json_flag(CLI::App* cmd, bool& json);
// Refuses (UsageError, exit 2) an output that goes to stdout ("-", /dev/stdout, a file stdout
// is redirected into) when --json would print there too.
void refuse_json_with_stdout_output(const std::string& output);

}  // namespace meshstream::tools
