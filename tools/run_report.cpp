// --json's object for convert, decimate and sort: see run_report.hpp.
#include "tools/run_report.hpp"

#include <sys/stat.h>
#include <cstdio>

namespace meshstream::tools {

nlohmann::ordered_json run_report_json(const RunReport& r, const Warnings& warnings) {
    auto files = [](const std::vector<RunFile>& list) {
        nlohmann::ordered_json out = nlohmann::ordered_json::array();
        for (const RunFile& f : list) out.push_back({{"path", f.path}, {"format", f.format}, {"gzip", f.gzip}});
        return out;
    };
    nlohmann::ordered_json j;
    j["command"] = r.command;
    j["inputs"] = files(r.inputs);
    j["outputs"] = files(r.outputs);
    j["triangles_in"] = r.triangles_in;
    j["triangles_out"] = r.triangles_out;
    j["seconds"] = r.seconds;
    j["triangles_per_second"] =
        r.seconds > 0 ? nlohmann::ordered_json(double(r.triangles_in) / r.seconds) : nlohmann::ordered_json(nullptr);
    j["peak_rss_bytes"] = r.peak_rss_bytes;
    if (!r.details.empty()) j[r.command] = r.details;
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const Warnings::Line& w : warnings.all(flag_name)) {
        nlohmann::ordered_json e = {{"code", w.code}, {"text", w.text}};
        if (w.count > 0) e["count"] = w.count;
        list.push_back(e);
    }
    j["warnings"] = list;
    return j;
}

void add_json_flag(CLI::App* cmd, bool& json) {
    cmd->add_flag("--json", json,
                  "print one JSON object on stdout at the end\n"
                  "Files, formats, counts, time, peak RSS, warnings with codes (docs/cli.md); stdout then holds "
                  "nothing else, so the output cannot be '-'");
}

void refuse_json_with_stdout_output(const std::string& output) {
    struct stat out, std_out;
    const bool same = output == "-" || (::stat(output.c_str(), &out) == 0 && ::fstat(1, &std_out) == 0 &&
                                        out.st_dev == std_out.st_dev && out.st_ino == std_out.st_ino);
    if (same)
        throw UsageError((output == "-" ? std::string("<stdout>") : output) +
                         ": --json prints its report on stdout, so the mesh cannot go there too: write it to a file");
}

}  // namespace meshstream::tools
