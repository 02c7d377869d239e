// --json's object for convert, decimate and sort (tools/run_report), built directly from
// statistics, and through the binary: one object on stdout and nothing else.
#include "tools/run_report.hpp"
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>

#include <string>

namespace meshstream::tools {
namespace {

using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;

TEST(RunReportJson, HoldsTheRunsFiguresAndCodedWarnings) {
    RunReport r;
    r.command = "convert";
    r.inputs = {{"in.ply.gz", "ply", true}};
    r.outputs = {{"out.stl", "stl", false}};
    r.triangles_in = 1000;
    r.triangles_out = 998;
    r.seconds = 0.5;
    r.peak_rss_bytes = 12345;
    r.details = {{"axis", "z"}};
    Warnings w;
    w.add("degenerate_triangles", "degenerate triangles removed", 2);
    w.note("channels_dropped", "colours dropped: stl output carries positions only");
    const nlohmann::ordered_json j = run_report_json(r, w);
    EXPECT_EQ(j.dump(),
              R"({"command":"convert","inputs":[{"path":"in.ply.gz","format":"ply","gzip":true}],)"
              R"("outputs":[{"path":"out.stl","format":"stl","gzip":false}],"triangles_in":1000,"triangles_out":998,)"
              R"("seconds":0.5,"triangles_per_second":2000.0,"peak_rss_bytes":12345,"convert":{"axis":"z"},)"
              R"("warnings":[{"code":"channels_dropped","text":"colours dropped: stl output carries positions only"},)"
              R"({"code":"degenerate_triangles","text":"degenerate triangles removed","count":2}]})");
    // No time measured: no rate, rather than a division by zero.
    r.seconds = 0;
    EXPECT_TRUE(run_report_json(r, Warnings{})["triangles_per_second"].is_null());
    EXPECT_TRUE(run_report_json(r, Warnings{})["warnings"].is_array());
}

const std::string kFixtures = MESHSTREAM_FIXTURES_DIR;

TEST(RunReportJson, EveryWritingCommandPrintsOneObject) {
    TempDir dir;
    const std::string coloured = kFixtures + "/ply/cactus_vcolor.binary_le.ply";
    struct Case {
        std::string command, args, output, out_format;
        uint64_t triangles_out;
    };
    const Case cases[] = {{"convert", "", "c.stl", "stl", 1236},
                          {"sort", "--axis z", "s.stl.gz", "stl", 1236},
                          {"decimate", "-r 0.5", "d.stl", "stl", 618}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.command);
        const std::string out = dir / c.output, json = dir / (c.command + ".json");
        const cli_test::CliRun r = run(c.command + " --json " + c.args + " " + coloured + " " + out + " > " + json);
        ASSERT_EQ(r.code, 0) << r.err;
        const std::string text = slurp(json);
        ASSERT_FALSE(text.empty());
        EXPECT_EQ(text.find('\n'), text.size() - 1) << text;  // one line, one object
        const nlohmann::json j = nlohmann::json::parse(text);
        EXPECT_EQ(j["command"], c.command);
        EXPECT_EQ(j["inputs"][0]["path"], coloured);
        EXPECT_EQ(j["inputs"][0]["format"], "ply");
        EXPECT_EQ(j["outputs"][0]["path"], out);
        EXPECT_EQ(j["outputs"][0]["format"], c.out_format);
        EXPECT_EQ(j["outputs"][0]["gzip"], c.output.ends_with(".gz"));
        EXPECT_EQ(j["triangles_in"], 1236);
        EXPECT_EQ(j["triangles_out"], c.triangles_out);
        EXPECT_GT(j["seconds"].get<double>(), 0);
        EXPECT_GT(j["peak_rss_bytes"].get<uint64_t>(), 1u << 20);
        // STL and decimate drop the colours, with the same code; the text is the warning's.
        bool dropped = false;
        for (const auto& w : j["warnings"])
            if (w["code"] == "channels_dropped") {
                dropped = true;
                EXPECT_NE(r.err.find(w["text"].get<std::string>()), std::string::npos) << r.err;
            }
        EXPECT_TRUE(dropped) << j.dump();
    }
    const nlohmann::json sorted = nlohmann::json::parse(slurp(dir / "sort.json"));
    EXPECT_EQ(sorted["sort"]["axis"], "z");
    const nlohmann::json decimated = nlohmann::json::parse(slurp(dir / "decimate.json"));
    EXPECT_EQ(decimated["decimate"]["target"], 618);
    EXPECT_EQ(decimated["decimate"]["forced_writes"], 0);
}

TEST(RunReportJson, RefusesAnOutputOnStdout) {
    TempDir dir;
    for (const char* cmd : {"convert", "sort", "decimate"}) {
        const cli_test::CliRun r = run(std::string(cmd) + " --json --to stl " + kFixtures + "/cube.bin.stl -");
        EXPECT_EQ(r.code, 2) << cmd;
        EXPECT_NE(r.err.find("meshstream: " + std::string(cmd) + ": <stdout>: --json prints its report on stdout"),
                  std::string::npos)
            << r.err;
        // The same file by another name: stdout redirected into the output.
        const cli_test::CliRun same =
            run(std::string(cmd) + " --json " + kFixtures + "/cube.bin.stl " + dir / "o.stl" + " >> " + dir / "o.stl");
        EXPECT_EQ(same.code, 2) << cmd;
    }
}

}  // namespace
}  // namespace meshstream::tools
