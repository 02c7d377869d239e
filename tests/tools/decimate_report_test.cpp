// tools/decimate_report: decimate's messages from plain statistics, no mesh needed.
#include "tools/decimate_report.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

using namespace meshstream;
using tools::DecimateFacts;
using tools::SortOutcome;

std::string warnings_of(const DecimateFacts& facts) {
    tools::Warnings w;
    tools::note_decimate_warnings(facts, w);
    std::string all;
    for (const std::string& line : w.lines()) all += line + "\n";
    return all;
}

DecimateFacts forced(uint64_t forced_writes) {
    DecimateFacts f;
    f.ratio = 0.01;
    f.input_name = "in.stl";
    f.stats.triangles_in = 100000;
    f.stats.target_triangles = 1000;
    f.stats.triangles_out = 1000 + forced_writes;
    f.stats.forced_writes = forced_writes;
    f.stats.premature_writes = forced_writes;
    return f;
}

TEST(DecimateReport, ForcedWritesNameTheRemedyThatFitsWhatIsKnownOfTheOrder) {
    DecimateFacts never = forced(500);
    never.buffer = 64;
    never.default_buffer = false;
    const std::string a = warnings_of(never);
    EXPECT_NE(a.find("500 triangles force-written at full resolution"), std::string::npos) << a;
    EXPECT_NE(a.find("(without --sort never decimate sorts it first; or run `meshstream sort` on it)"),
              std::string::npos)
        << a;
    EXPECT_NE(a.find("`meshstream info --order --ratio 0.01 --buffer 64` tells which"), std::string::npos) << a;
    EXPECT_NE(a.find("output has 1500 triangles instead of the target 1000 (the triangles force-written"),
              std::string::npos)
        << a;

    DecimateFacts could_not = forced(500);
    could_not.sort.kind = SortOutcome::Kind::kCouldNot;
    could_not.sort.why_not = "sorting failed: disk full";
    const std::string b = warnings_of(could_not);
    EXPECT_NE(b.find("(decimate could not sort it first: sorting failed: disk full; run `meshstream sort` on it)"),
              std::string::npos)
        << b;

    DecimateFacts sorted = forced(500);
    sorted.used_axis = 1;
    sorted.stats.sweep_direction = 1;
    const std::string c = warnings_of(sorted);
    EXPECT_NE(c.find("; the input is sorted, so the buffer is too small for it at this ratio: raise --buffer "
                     "(`meshstream info --order --ratio 0.01` estimates the buffer it needs)"),
              std::string::npos)
        << c;
    EXPECT_EQ(c.find("--sort"), std::string::npos) << c;
}

TEST(DecimateReport, NoWarningsForARunThatLandedOnItsTarget) {
    DecimateFacts f = forced(0);
    EXPECT_EQ(warnings_of(f), "");
}

TEST(DecimateReport, AnUnweldedSurfaceAndAMissByOneAreSaid) {
    DecimateFacts f = forced(0);
    f.stats.boundary_edges = 250000;
    f.stats.triangles_out = 1001;
    const std::string w = warnings_of(f);
    EXPECT_NE(w.find("250000 edges had no partner, 2.5 per triangle"), std::string::npos) << w;
    EXPECT_NE(w.find("output has 1001 triangles instead of the target 1000 (a collapse removes two triangles"),
              std::string::npos)
        << w;
}

TEST(DecimateReport, TheSortNoticeSaysWhyAndWhatItCost) {
    SortOutcome none;
    EXPECT_EQ(tools::sort_notice(none), "");
    SortOutcome automatic;
    automatic.kind = SortOutcome::Kind::kSorted;
    automatic.axis = 2;
    automatic.detected_at = 409600;
    automatic.attempt_seconds = 1.5;
    automatic.sort_seconds = 0.25;
    automatic.temp_bytes = 36000000;
    EXPECT_EQ(tools::sort_notice(automatic),
              "sorted along z first (forced writes began after 409.6 k triangles read, so the input is in no order "
              "this buffer holds; `--sort never` decimates it as read): 1.75 s (1.50 s of it in the first attempt), "
              "36.0 MB of temporary disk");
    SortOutcome asked = automatic;
    asked.requested = true;
    asked.attempt_seconds = 0;
    asked.temp_bytes = 0;
    EXPECT_EQ(tools::sort_notice(asked), "sorted along z first (--sort always): 0.25 s, in memory");
}

}  // namespace
