// tools/common: the helpers the commands share, called directly (the commands themselves are
// tested through the binary in cli_*_test.cpp).
#include "tools/common.hpp"

#include <gtest/gtest.h>

namespace meshstream::tools {
namespace {

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

}  // namespace
}  // namespace meshstream::tools
