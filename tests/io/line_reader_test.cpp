// Tests of io::LineReader: lines without their ends, continuation joining, where each line
// began, and its two errors.
#include "io/line_reader.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

using namespace meshstream;
using meshstream::test::spit;
using meshstream::test::TempDir;

namespace {

struct Line {
    std::string text;
    uint64_t number, offset;
    bool operator==(const Line&) const = default;
};

std::vector<Line> lines_of(const std::string& path, bool join, bool* unterminated = nullptr) {
    auto source = io::ByteSource::open(path);
    io::LineReader reader(*source, join);
    std::vector<Line> out;
    std::string_view line;
    while (reader.next(line)) out.push_back({std::string(line), reader.line_number(), reader.line_offset()});
    if (unterminated) *unterminated = reader.unterminated();
    return out;
}

io::Error error_of(const std::string& path) {
    try {
        lines_of(path, true);
    } catch (const io::Error& e) {
        return e;
    }
    ADD_FAILURE() << "no io::Error";
    return io::Error(path, "none");
}

}  // namespace

TEST(LineReader, LinesLoseTheirEndsAndTrailingBlanksAndKnowWhereTheyBegan) {
    TempDir dir;
    spit(dir / "a.txt", "v 1 2 3  \r\n\n  f 1 2 3\t\nlast");
    bool unterminated = false;
    const std::vector<Line> lines = lines_of(dir / "a.txt", false, &unterminated);
    const std::vector<Line> want = {{"v 1 2 3", 1, 0}, {"", 2, 11}, {"  f 1 2 3", 3, 12}, {"last", 4, 23}};
    EXPECT_EQ(lines, want);
    EXPECT_TRUE(unterminated);
    spit(dir / "b.txt", "one\ntwo\n");
    EXPECT_EQ(lines_of(dir / "b.txt", false, &unterminated).size(), 2u);
    EXPECT_FALSE(unterminated);
    spit(dir / "empty.txt", "");
    EXPECT_TRUE(lines_of(dir / "empty.txt", false).empty());
}

TEST(LineReader, ContinuationLinesJoinWithASpaceOnlyWhenAsked) {
    TempDir dir;
    spit(dir / "c.txt", "f 1 2 \\\r\n 3 4\nv 0 \\\n0 \\\n0\nend \\");
    const std::vector<Line> joined = lines_of(dir / "c.txt", true);
    const std::vector<Line> want = {{"f 1 2   3 4", 1, 0}, {"v 0  0  0", 3, 14}, {"end  ", 6, 26}};
    EXPECT_EQ(joined, want);
    const std::vector<Line> plain = lines_of(dir / "c.txt", false);
    ASSERT_EQ(plain.size(), 6u);
    EXPECT_EQ(plain[0].text, "f 1 2 \\");
    EXPECT_EQ(plain[5].text, "end \\");
}

TEST(LineReader, CarriageReturnInsideALineIsAnErrorAtThatLine) {
    TempDir dir;
    spit(dir / "mac.txt", "first\nv 1 2 3\rv 4 5 6\r");
    io::Error e = error_of(dir / "mac.txt");
    EXPECT_EQ(e.file(), dir / "mac.txt");
    EXPECT_EQ(e.line(), 2u);
    EXPECT_EQ(e.byte_offset(), 6u);
    EXPECT_NE(e.message().find("carriage return inside a line"), std::string::npos) << e.what();
}

TEST(LineReader, ALineLongerThanTheBufferIsAnErrorNamingIt) {
    TempDir dir;
    spit(dir / "long.txt", "short\n" + std::string(io::ByteSource::kBufferBytes + 10, 'x') + "\n");
    io::Error e = error_of(dir / "long.txt");
    EXPECT_EQ(e.line(), 2u);
    EXPECT_EQ(e.byte_offset(), 6u);
    EXPECT_NE(e.message().find("line longer than 1 MiB"), std::string::npos) << e.what();
    auto source = io::ByteSource::open(dir / "long.txt");
    io::LineReader header(*source, false, "header line");
    std::string_view line;
    ASSERT_TRUE(header.next(line));
    try {
        header.next(line);
        FAIL() << "no io::Error";
    } catch (const io::Error& err) {
        EXPECT_NE(err.message().find("header line longer than 1 MiB"), std::string::npos) << err.what();
    }
}
