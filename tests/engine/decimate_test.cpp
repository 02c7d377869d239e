// engine::decimate_file, decimate_part, convert_file and sort_file as a library user calls them:
// exact counts, ranges on two threads (each reading its own records of a binary STL or a
// triangle stream with a count), part files
// merged to the bytes two threads write, the
// progress a sink sees, cancellation that leaves nothing behind, and settings refused as
// io::OptionError naming the setting.
#include "engine/decimate.hpp"
#include "engine/convert.hpp"
#include "io/error.hpp"
#include "io/format.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <string>
#include <vector>

namespace meshstream {
namespace {

using test::slurp;
using test::TempDir;

const std::string kBunny = std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl";  // 69 451 triangles
constexpr uint64_t kBunnyTriangles = 69451;

// Records what the engine reports; cancels at the `cancel_at`-th update when asked to.
class Recorder final : public engine::ProgressSink {
public:
    explicit Recorder(int cancel_at = -1) : cancel_at_(cancel_at) {}
    void phase(std::string label, std::optional<uint64_t>) override { phases.push_back(std::move(label)); }
    void update(uint64_t done) override { count(done); }
    void update(uint64_t done, uint64_t, std::optional<uint64_t>) override { count(done); }
    void status(const std::string&) override {}
    bool cancelled() const override { return cancel_at_ >= 0 && updates >= cancel_at_; }
    std::vector<std::string> phases;
    int updates = 0;
    uint64_t last = 0;

private:
    void count(uint64_t done) {
        ++updates;
        last = done;
    }
    int cancel_at_;
};

engine::DecimateSettings bunny_settings(const std::string& output) {
    engine::DecimateSettings s;
    s.input = kBunny;
    s.output = output;
    s.ratio = 0.1;
    s.buffer = engine::kMinRangeBuffer;  // small enough for the bunny to make two ranges
    return s;
}

TEST(EngineDecimate, OneThreadLandsOnTheTarget) {
    TempDir dir;
    Recorder progress;
    const engine::DecimateResult r = engine::decimate_file(bunny_settings(dir / "out.stl"), progress);
    EXPECT_EQ(r.triangles_in, kBunnyTriangles);
    EXPECT_EQ(r.triangles_out, 6945u);  // round(0.1 * 69451)
    EXPECT_EQ(r.facts.stats.triangles_out, 6945u);
    EXPECT_EQ(r.facts.threads, 1u);
    EXPECT_EQ(r.input_format, "stl");
    EXPECT_EQ(r.output_format, "stl");
    EXPECT_TRUE(r.warnings.empty());
    // Binary STL: 84 bytes of header and count, 50 a triangle.
    EXPECT_EQ(slurp(dir / "out.stl").size(), 84u + 50u * 6945u);
    EXPECT_NE(std::find(progress.phases.begin(), progress.phases.end(), "decimating"), progress.phases.end());
    EXPECT_GT(progress.updates, 0);
}

TEST(EngineDecimate, TwoThreadsCutTwoRangesDeterministically) {
    TempDir dir;
    engine::DecimateSettings s = bunny_settings(dir / "a.ply");
    s.threads = 2;
    engine::QuietProgress quiet;
    const engine::DecimateResult a = engine::decimate_file(s, quiet);
    EXPECT_EQ(a.facts.threads, 2u);
    EXPECT_EQ(a.triangles_out, 6945u);
    EXPECT_EQ(a.facts.seam_buffer, decimate::seam_pass_buffer(s.buffer));
    s.output = dir / "b.ply";
    engine::decimate_file(s, quiet);
    EXPECT_EQ(slurp(dir / "a.ply"), slurp(dir / "b.ply"));
}

TEST(EngineDecimate, PartJobsMergeToTheBytesOfTwoThreads) {
    TempDir dir;
    engine::QuietProgress quiet;
    engine::DecimateSettings threads = bunny_settings(dir / "threads.stl");
    threads.threads = 2;
    engine::decimate_file(threads, quiet);

    engine::DecimateSettings part = bunny_settings(dir / "1.part");
    part.output_format = "stl";  // the merge's output format: the channels carried
    part.part = engine::PartIndex{1, 2};
    const engine::PartResult p = engine::decimate_part(part, quiet);
    EXPECT_EQ(p.range_first, 0u);
    EXPECT_EQ(p.range_end, kBunnyTriangles / 2);
    EXPECT_EQ(p.triangles_in, kBunnyTriangles / 2);

    engine::DecimateSettings merge = bunny_settings(dir / "merged.stl");
    merge.part = engine::PartIndex{2, 2};
    merge.merge = {dir / "1.part"};
    const engine::DecimateResult m = engine::decimate_file(merge, quiet);
    EXPECT_EQ(m.facts.parts, 2u);
    ASSERT_EQ(m.part_files.size(), 1u);
    EXPECT_EQ(m.part_files[0].k, 1u);
    EXPECT_EQ(slurp(dir / "merged.stl"), slurp(dir / "threads.stl"));
}

// A triangle's corners, rotated to start at the least (the winding kept): one key per triangle
// whatever corner a writer starts from.
using TriangleKey = std::array<float, 9>;

// The triangles of a mesh file, as sorted keys.
std::vector<TriangleKey> triangle_keys(const std::string& path) {
    io::Input in = io::open_input(path);
    io::TriangleChunk chunk;
    std::vector<TriangleKey> keys;
    while (in.reader->next(chunk))
        for (size_t i = 0; i < chunk.size(); ++i) {
            const float* t = chunk.xyz().data() + 9 * i;
            size_t first = 0;
            for (size_t c = 1; c < 3; ++c)
                if (std::lexicographical_compare(t + 3 * c, t + 3 * c + 3, t + 3 * first, t + 3 * first + 3)) first = c;
            TriangleKey key;
            for (size_t c = 0; c < 3; ++c) std::copy_n(t + 3 * ((first + c) % 3), 3, key.data() + 3 * c);
            keys.push_back(key);
        }
    std::sort(keys.begin(), keys.end());
    return keys;
}

TEST(EngineDecimate, RangesOfABinaryStlReadTheirOwnRecords) {
    // The bunny with three degenerate records, which the read loop drops. A range goes to the
    // record where its triangles start when nothing before it is dropped, else it starts again
    // from the input's start; either way the output is the bytes of part jobs, which read their
    // way to their ranges. With a ratio of 1 every triangle passes through, so the output holds
    // each of the bunny's once exactly when the ranges read every record once.
    const std::string bunny = slurp(kBunny);
    const uint64_t records = kBunnyTriangles + 3;
    for (const std::vector<uint64_t>& at : {std::vector<uint64_t>{40000, 50000, 60000},  // in the last range
                                            std::vector<uint64_t>{5, 1000, 60000}}) {      // two in the first
        TempDir dir;
        std::string stl = bunny.substr(0, 80);
        const auto count = uint32_t(records);
        stl.append(reinterpret_cast<const char*>(&count), 4);
        char degenerate[50] = {};
        const float corners[9] = {1, 2, 3, 1, 2, 3, 4, 5, 6};  // two corners at one position
        std::memcpy(degenerate + 12, corners, sizeof corners);
        for (uint64_t i = 0; i < kBunnyTriangles; ++i) {
            const uint64_t next = (stl.size() - 84) / 50;  // the record appended next
            if (std::find(at.begin(), at.end(), next) != at.end()) stl.append(degenerate, 50);
            stl.append(bunny, 84 + 50 * i, 50);
        }
        ASSERT_EQ(stl.size(), 84 + 50 * records);
        test::spit(dir / "in.stl", stl);

        engine::QuietProgress quiet;
        engine::DecimateSettings s = bunny_settings(dir / "threads.stl");
        s.input = dir / "in.stl";
        s.ratio = 1;
        s.threads = 2;
        const engine::DecimateResult r = engine::decimate_file(s, quiet);
        EXPECT_EQ(r.facts.threads, 2u);
        EXPECT_EQ(r.triangles_in, records);
        EXPECT_EQ(r.facts.skipped, 3u);
        EXPECT_EQ(r.triangles_out, kBunnyTriangles);
        EXPECT_EQ(triangle_keys(dir / "threads.stl"), triangle_keys(kBunny)) << at[0];

        s.ratio = 0.1;
        const engine::DecimateResult t = engine::decimate_file(s, quiet);
        EXPECT_EQ(t.triangles_in, records);
        EXPECT_EQ(t.facts.skipped, 3u);
        engine::DecimateSettings part = s;
        part.threads = 1;
        part.output = dir / "1.part";
        part.output_format = "stl";
        part.part = engine::PartIndex{1, 2};
        const engine::PartResult p = engine::decimate_part(part, quiet);
        EXPECT_EQ(p.range_end, records / 2);
        EXPECT_EQ(p.triangles_in, records / 2);
        engine::DecimateSettings merge = s;
        merge.threads = 1;
        merge.output = dir / "merged.stl";
        merge.part = engine::PartIndex{2, 2};
        merge.merge = {dir / "1.part"};
        const engine::DecimateResult m = engine::decimate_file(merge, quiet);
        EXPECT_EQ(m.triangles_in, records);
        EXPECT_EQ(m.facts.skipped, 3u);
        EXPECT_EQ(slurp(dir / "merged.stl"), slurp(dir / "threads.stl")) << at[0];
    }
}

TEST(EngineDecimate, RangesOfATriangleStreamWithACountReadTheirOwnRecords) {
    // The bunny as meshstream's triangle stream with its count, in chunks of 1000: a range goes
    // past whole chunks to its first triangle (io::Reader::select_triangles). Gzipped, it cannot,
    // and reads its way there: the same output, byte for byte; at a ratio of 1, every triangle once.
    TempDir dir;
    for (const std::string name : {"in.mstream", "in.mstream.gz"}) {
        io::TriangleInput in(io::open_input(kBunny), io::BadTriangles::kKeep);
        io::WriteOptions wo;
        wo.triangle_count = kBunnyTriangles;
        io::Output out = io::open_output(dir / name, "stream", wo, 6);
        io::TriangleChunk chunk(1000, in.header().channels);
        while (in.next(chunk)) out.write(chunk);
        out.finish();
    }
    engine::QuietProgress quiet;
    for (const double ratio : {1.0, 0.1}) {
        for (const std::string name : {"in.mstream", "in.mstream.gz"}) {
            engine::DecimateSettings s = bunny_settings(dir / (name + ".stl"));
            s.input = dir / name;
            s.ratio = ratio;
            s.threads = 2;
            const engine::DecimateResult r = engine::decimate_file(s, quiet);
            EXPECT_EQ(r.facts.threads, 2u) << name;
            EXPECT_EQ(r.triangles_in, kBunnyTriangles) << name;
        }
        EXPECT_EQ(slurp(dir / "in.mstream.stl"), slurp(dir / "in.mstream.gz.stl")) << ratio;
        if (ratio == 1.0) {
            EXPECT_EQ(triangle_keys(dir / "in.mstream.stl"), triangle_keys(kBunny));
        }
    }
}

TEST(EngineDecimate, CancelledLeavesNoOutputBehind) {
    for (const unsigned threads : {1u, 2u}) {
        TempDir dir;
        engine::DecimateSettings s = bunny_settings(dir / "out.glb");
        s.threads = threads;
        Recorder progress(/*cancel_at=*/1);
        EXPECT_THROW(engine::decimate_file(s, progress), engine::Cancelled) << threads << " threads";
        EXPECT_EQ(dir.file_count(), 0u) << threads << " threads";
    }
}

TEST(EngineDecimate, SettingsThatCannotWorkAreOptionErrors) {
    TempDir dir;
    engine::QuietProgress quiet;
    engine::DecimateSettings s = bunny_settings(dir / "out.stl");
    s.ratio.reset();
    s.target = kBunnyTriangles + 1;
    try {
        engine::decimate_file(s, quiet);
        FAIL() << "a target above the input was taken";
    } catch (const io::OptionError& e) {
        EXPECT_EQ(e.setting(), io::Setting::kTarget);
        EXPECT_NE(std::string(e.what()).find("is more than the 69451 triangles of the input"), std::string::npos)
            << e.what();
    }
    // The output over the input.
    s = bunny_settings(kBunny);
    try {
        engine::decimate_file(s, quiet);
        FAIL() << "the input was overwritten";
    } catch (const io::OptionError& e) {
        EXPECT_EQ(e.setting(), io::Setting::kOutput);
    }
    EXPECT_EQ(dir.file_count(), 0u);
}

TEST(EngineConvert, ConvertAndSortKeepEveryTriangle) {
    TempDir dir;
    Recorder progress;
    engine::ConvertSettings c;
    c.input = kBunny;
    c.output = dir / "bunny.ply";
    c.threads = 2;
    const engine::ConvertResult converted = engine::convert_file(c, progress);
    EXPECT_EQ(converted.triangles_in, kBunnyTriangles);
    EXPECT_EQ(converted.triangles_out, kBunnyTriangles);
    EXPECT_EQ(converted.output_format, "ply");

    engine::SortSettings s;
    s.input = dir / "bunny.ply";
    s.output = dir / "sorted.stl";
    s.axis = 1;
    const engine::SortResult sorted = engine::sort_file(s, progress);
    EXPECT_EQ(sorted.axis, 1);
    EXPECT_EQ(sorted.triangles_out, kBunnyTriangles);
    // The sorted file says so, and the decimator takes its word.
    const io::Input in = io::open_input(dir / "sorted.stl");
    EXPECT_EQ(in.reader->header().sorted_axis, std::optional<int>(1));

    Recorder cancel(/*cancel_at=*/1);
    s.output = dir / "cancelled.stl";
    EXPECT_THROW(engine::sort_file(s, cancel), engine::Cancelled);
    EXPECT_FALSE(std::filesystem::exists(dir / "cancelled.stl"));
}

}  // namespace
}  // namespace meshstream
