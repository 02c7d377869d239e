// io::Error formats its position like a compiler diagnostic.
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
