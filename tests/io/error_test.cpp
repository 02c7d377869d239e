// io::Error formats its position like a compiler diagnostic; settings mentioned in a message
// read as words in what() and as a program's own names through describe() and render().
#include "io/error.hpp"

#include <gtest/gtest.h>

using meshstream::io::Error;

TEST(Error, NamesFileAndLine) {
    Error e("scan.stl", Error::kNoOffset, 1207, "expected 'endloop', found 'endfacet'");
    EXPECT_STREQ(e.what(), "scan.stl:1207: expected 'endloop', found 'endfacet'");
    EXPECT_EQ(e.line(), 1207u);
    EXPECT_EQ(e.byte_offset(), Error::kNoOffset);
}

TEST(Error, NamesFileAndByteOffset) {
    Error e("scan.stl", 84, 0, "header promises 69451 triangles, file holds 1200");
    EXPECT_STREQ(e.what(), "scan.stl: byte 84: header promises 69451 triangles, file holds 1200");
}

TEST(Error, ByteOffsetZeroIsAPosition) {
    Error e("a.ply", 0, 0, "not a PLY file");
    EXPECT_STREQ(e.what(), "a.ply: byte 0: not a PLY file");
}

TEST(Error, QuotesBinaryTokens) { EXPECT_EQ(meshstream::io::quote_token(std::string_view("ab\x01", 3)), "'ab\\x01'"); }

namespace io = meshstream::io;
using io::mention;
using io::Setting;

namespace {

// A program's own names for the settings, as the command's flags are.
std::string flag_of(Setting s) {
    switch (s) {
        case Setting::kMemory: return "--memory";
        case Setting::kTmpdir: return "--tmpdir";
        default: return "--other";
    }
}

}  // namespace

TEST(Error, MentionsReadAsSettingWordsInWhatAndAsAProgramsNamesInDescribe) {
    const Error e("big.glb", 12, 0,
                  "buffer of 3 GiB passes the memory budget of 1 GiB; raise " + mention(Setting::kMemory));
    EXPECT_STREQ(e.what(),
                 "big.glb: byte 12: buffer of 3 GiB passes the memory budget of 1 GiB; raise the memory budget");
    EXPECT_EQ(e.message(), "buffer of 3 GiB passes the memory budget of 1 GiB; raise the memory budget");
    EXPECT_EQ(e.describe(flag_of),
              "big.glb: byte 12: buffer of 3 GiB passes the memory budget of 1 GiB; raise --memory");
    EXPECT_EQ(e.raw_message(), "buffer of 3 GiB passes the memory budget of 1 GiB; raise " + mention(Setting::kMemory));
    EXPECT_EQ(io::render(e.raw_what(), flag_of), e.describe(flag_of));
}

TEST(Error, AnErrorQuotingAnotherKeepsItsMentions) {
    const Error inner("/tmp/run-1", 4096, 0, "write failed: No space left on device");
    const Error outer(inner.file(), inner.byte_offset(), inner.line(),
                      inner.raw_message() + " (temporary file; " + mention(Setting::kTmpdir) + " picks another)");
    EXPECT_STREQ(outer.what(),
                 "/tmp/run-1: byte 4096: write failed: No space left on device (temporary file; the "
                 "temporary-directory setting picks another)");
    EXPECT_EQ(outer.describe(flag_of),
              "/tmp/run-1: byte 4096: write failed: No space left on device (temporary file; "
              "--tmpdir picks another)");
    // Quoted twice, and through the base class's raw text (as across MPI ranks).
    const Error twice("x", inner.file() + ": " + outer.raw_message());
    EXPECT_EQ(twice.describe(flag_of),
              "x: /tmp/run-1: write failed: No space left on device (temporary file; --tmpdir picks another)");
    const meshstream::Error copied(outer.raw_what());
    EXPECT_STREQ(copied.what(), outer.what());
    EXPECT_EQ(copied.describe(flag_of), outer.describe(flag_of));
}

TEST(Error, OptionErrorNamesItsSettingAndTheValue) {
    const io::OptionError e(Setting::kDracoPositionBits,
                            "x.drc: " + mention(Setting::kDracoPositionBits) + " must be 1-30, got 31");
    EXPECT_STREQ(e.what(), "x.drc: the Draco position bits must be 1-30, got 31");
    EXPECT_EQ(e.setting(), Setting::kDracoPositionBits);
    EXPECT_EQ(e.describe(flag_of), "x.drc: --other must be 1-30, got 31");
    // One family: a caller catches both kinds as meshstream::Error.
    try {
        throw e;
    } catch (const meshstream::Error& caught) {
        EXPECT_STREQ(caught.what(), e.what());
    }
    try {
        throw Error("a.stl", 0, 0, "not an STL file");
    } catch (const meshstream::Error& caught) {
        EXPECT_STREQ(caught.what(), "a.stl: byte 0: not an STL file");
    }
}

TEST(Error, EverySettingHasWordsAndNoFlag) {
    for (int i = 0; i < io::kSettingCount; ++i) {
        const std::string words(io::setting_words(Setting(i)));
        SCOPED_TRACE(i);
        EXPECT_FALSE(words.empty());
        EXPECT_EQ(words.find("--"), std::string::npos);
        EXPECT_EQ(io::render(mention(Setting(i))), words);
        for (int j = 0; j < i; ++j) EXPECT_NE(words, io::setting_words(Setting(j))) << j;
    }
}

TEST(Error, FileContentCannotForgeAMention) {
    // Messages quote file content through printable(), which escapes the mark.
    const std::string forged = mention(Setting::kMemory);
    const Error e("a.obj", 3, 0, "unknown statement " + io::quote_token(forged));
    EXPECT_STREQ(e.what(), "a.obj: byte 3: unknown statement '\\x1e\\x05\\x1e'");
    EXPECT_EQ(e.describe(flag_of), e.what());
}
