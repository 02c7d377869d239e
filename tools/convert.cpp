// `meshstream convert IN OUT`: the command line of engine::convert_file (engine/convert.hpp),
// which streams triangles between any two registered formats, one chunk at a time.
#include "engine/convert.hpp"
#include "io/error.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/input_filter.hpp"
#include "tools/jobs.hpp"
#include "tools/run_report.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

namespace meshstream::tools {

nlohmann::ordered_json convert_job(const ConvertOptions& opt, engine::ProgressSink* progress) {
    const auto start = std::chrono::steady_clock::now();
    if (opt.json) refuse_json_with_stdout_output(opt.output);
    const io::Format& out_format = resolve_output_format(opt.output, opt.write);
    auto settings = job_settings<engine::ConvertSettings>(opt.input, opt.output, out_format, opt.read, opt.write);
    settings.clean = opt.clean;
    settings.threads = opt.threads;
    engine::ConvertResult result;
    {
        std::optional<Progress> bar;
        result = engine::convert_file(settings, progress ? *progress : bar.emplace("converting", std::nullopt));
    }
    Warnings warnings = result.warnings;
    note_unused_write_flags(opt.write, out_format, opt.output, warnings);
    print_warnings(warnings);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return run_report_json(run_report_of("convert", opt.input, opt.output, result, seconds), warnings);
}

CLI::App* convert_command(CLI::App& app, ConvertOptions& options) {
    ConvertOptions* opt = &options;
    CLI::App* cmd = app.add_subcommand(
        "convert", "any format to any other, every triangle and channel the output can hold kept\n" + kInOutText);
    cmd->add_option("IN", opt->input, "input mesh ('-' = stdin)")->required();
    cmd->add_option("OUT", opt->output, "output mesh ('-' = stdout)")->required();
    add_write_flags(cmd, opt->write);
    cmd->get_option("--compress")->group("Options");
    add_clean_flag(cmd, opt->clean);
    add_drop_flag(cmd, opt->read);
    add_json_flag(cmd, opt->json);
    add_threads_option(cmd, opt->threads, "read and write on threads of their own");
    add_read_flags(cmd, opt->read);
    describe_memory_for_writing(cmd);
    cmd->footer(
        "  meshstream convert scan.ply scan.glb --compress meshopt\n"
        "  meshstream convert scan.stl - --to ply | gzip > scan.ply.gz");
    return cmd;
}

void add_convert(CLI::App& app) {
    auto opt = std::make_shared<ConvertOptions>();
    run_when_parsed(convert_command(app, *opt), opt, [](ConvertOptions& o) { return convert_job(o); });
}

}  // namespace meshstream::tools
