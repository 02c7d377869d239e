// tools/common: the helpers the commands share, called directly (the commands themselves are
// tested through the binary in cli_*_test.cpp).
#include "tools/common.hpp"

#include "io/error.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

namespace meshstream::tools {
namespace {

// The libraries' messages mention settings; the command names them by its flags, so that what
// it prints does not change with the library's words for them.
TEST(FlagName, EverySettingHasTheFlagThatSetsIt) {
    EXPECT_EQ(flag_name(io::Setting::kMemory), "--memory");
    EXPECT_EQ(flag_name(io::Setting::kDracoPositionBits), "--draco-qp");
    EXPECT_EQ(flag_name(io::Setting::kAttributes), "--attributes");
    EXPECT_EQ(flag_name(io::Setting::kInput), "IN");
    for (int i = 0; i < io::kSettingCount; ++i) {
        const std::string flag = flag_name(io::Setting(i));
        SCOPED_TRACE(flag);
        // A flag, an argument, or (set by no flag) the library's words.
        EXPECT_TRUE(flag.starts_with("--") || flag == "IN" || flag == "OUT" ||
                    flag == io::setting_words(io::Setting(i)));
        for (int j = 0; j < i; ++j) EXPECT_NE(flag, flag_name(io::Setting(j))) << j;
    }
}

TEST(FlagName, ErrorsAreDescribedWithFlagsAndQuotedErrorsKeepThem) {
    const io::Error read("big.glb", 12, 0,
                         "over the memory budget of 1 MiB; raise " + io::mention(io::Setting::kMemory));
    EXPECT_STREQ(read.what(), "big.glb: byte 12: over the memory budget of 1 MiB; raise the memory budget");
    EXPECT_EQ(describe_error(read), "big.glb: byte 12: over the memory budget of 1 MiB; raise --memory");
    const io::Error quoting(read.file(), read.byte_offset(), read.line(), read.raw_message() + " (sorting)");
    EXPECT_EQ(describe_error(quoting), "big.glb: byte 12: over the memory budget of 1 MiB; raise --memory (sorting)");
    const io::OptionError option(io::Setting::kDracoLevel,
                                 io::mention(io::Setting::kDracoLevel) + " must be 0-10, got 11");
    EXPECT_EQ(describe_error(option), "--draco-cl must be 0-10, got 11");
    EXPECT_EQ(describe_error(std::runtime_error("plain")), "plain");
}

TEST(DropList, NamesTheKindsNotRead) {
    const io::ChannelKinds all = kept_channel_kinds("");
    EXPECT_TRUE(all.normals && all.colors && all.uvs && all.extras && all.materials);
    const io::ChannelKinds no_colours = kept_channel_kinds("colors");
    EXPECT_TRUE(no_colours.normals && no_colours.uvs && no_colours.extras && no_colours.materials);
    EXPECT_FALSE(no_colours.colors);
    const io::ChannelKinds some = kept_channel_kinds("normals,uvs,extra");
    EXPECT_FALSE(some.normals || some.uvs || some.extras);
    EXPECT_TRUE(some.colors && some.materials);
    EXPECT_FALSE(kept_channel_kinds("materials,").materials);
}

TEST(DropList, AnUnknownNameIsNamed) {
    try {
        kept_channel_kinds("normals,colours");
        FAIL() << "no error";
    } catch (const CLI::ValidationError& e) {
        EXPECT_NE(std::string(e.what()).find("unknown channel 'colours' (one of: normals, colors, uvs, extra"),
                  std::string::npos)
            << e.what();
    }
}

TEST(DropList, SetsTheReadOptionsChannels) {
    ReadFlags flags;
    flags.drop = "colors";
    const io::ReadOptions options = flags.options();
    EXPECT_FALSE(options.channels.colors);
    EXPECT_TRUE(options.channels.normals);
    io::Channels file;
    file.normal = true;
    file.color = io::ColorFormat{};
    const io::Channels read = options.channels.of(file);
    EXPECT_TRUE(read.normal);
    EXPECT_FALSE(read.color.has_value());
}

// --memory's default for Draco and glTF output: half of MemAvailable, from 256 MiB to 64 GiB.
TEST(WholeMeshMemory, IsHalfTheAvailableMemoryWithinAFloorAndACeiling) {
    const uint64_t mib = uint64_t{1} << 20;
    EXPECT_EQ(whole_mesh_memory("MemTotal:       32768000 kB\nMemFree:         1000000 kB\n"
                                "MemAvailable:    8388608 kB\nBuffers:           12 kB\n"),
              4096 * mib);
    EXPECT_EQ(whole_mesh_memory("MemAvailable: 2000000 kB"), 2000000 * uint64_t{1024} / 2);
    EXPECT_EQ(whole_mesh_memory("MemAvailable:     262144 kB\n"), 256 * mib);    // 128 MiB: the floor
    EXPECT_EQ(whole_mesh_memory("MemAvailable:  268435456 kB\n"), 65536 * mib);  // 128 GiB: the ceiling
    // Without a MemAvailable line (kernels before 3.14), or one not understood: the floor.
    EXPECT_EQ(whole_mesh_memory("MemTotal:       32768000 kB\nMemFree:        16000000 kB\n"), 256 * mib);
    EXPECT_EQ(whole_mesh_memory("MemAvailable:    lots kB\n"), 256 * mib);
    EXPECT_EQ(whole_mesh_memory(""), 256 * mib);
}

// An explicit --memory is the writer's budget whatever the output; without it only a writer
// that holds the whole mesh gets the larger default.
TEST(WholeMeshMemory, AppliesToWholeMeshWritersWithoutMemoryOnly) {
    // A fixed meminfo: /proc/meminfo's MemAvailable moves between two reads on a busy machine.
    test::TempDir dir;
    const std::string meminfo = (dir.path() / "meminfo").string();
    std::ofstream(meminfo) << "MemAvailable:    8000000 kB\n";
    ASSERT_EQ(::setenv("MESHSTREAM_MEMINFO", meminfo.c_str(), 1), 0);
    ReadFlags read;
    WriteFlags write;
    const io::Format& glb = *io::find_format("glb");
    const io::Format& stl = *io::find_format("stl");
    EXPECT_EQ(write.options(read, glb).memory_budget_bytes, whole_mesh_memory());
    EXPECT_EQ(write.options(read, stl).memory_budget_bytes, kStreamingMemory);
    EXPECT_EQ(read.options().memory_budget_bytes, kStreamingMemory);
    read.memory = "64M";
    EXPECT_EQ(write.options(read, glb).memory_budget_bytes, uint64_t{64} << 20);
    EXPECT_EQ(write.options(read, stl).memory_budget_bytes, uint64_t{64} << 20);
    EXPECT_EQ(whole_mesh_memory(), 8000000 * uint64_t{1024} / 2);
    ::unsetenv("MESHSTREAM_MEMINFO");
}

}  // namespace
}  // namespace meshstream::tools
