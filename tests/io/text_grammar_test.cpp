// The one grammar of numbers and integers in the text formats (io/text_tokens.hpp): the
// functions themselves, then the same token list through ASCII STL (a vertex coordinate), PLY
// ascii (a float and a double x), OBJ (a `v` coordinate) and MTL (a `Kd` component), which
// must all accept it with the same value or all refuse it, quoting it; then the same for
// integers through OBJ and PLY face indices and PLY list lengths and element counts.
#include "io/text_tokens.hpp"

#include "indexed_test_util.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

using namespace meshstream;
using test::TempDir;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

// Equal bits, or both NaN (of the same sign): -0 is not 0 here.
bool same(float a, float b) {
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) && std::signbit(a) == std::signbit(b);
    return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b);
}

struct NumberCase {
    const char* token;
    std::optional<float> value;  // nullopt: not a number
};

const NumberCase kNumbers[] = {
    {"1", 1.0f},
    {"-1", -1.0f},
    {"+1", 1.0f},
    {"0", 0.0f},
    {"-0", -0.0f},
    {"007", 7.0f},
    {"1.5e-3", 1.5e-3f},
    {"1E5", 1e5f},
    {"1e+5", 1e5f},
    {".5", 0.5f},
    {"5.", 5.0f},
    {"-.5", -0.5f},
    {"+.5", 0.5f},
    {"1e-40", 1e-40f},  // a subnormal float
    {"1e400", kInf},    // past the range: ±infinity
    {"-1e400", -kInf},
    {"+1e400", kInf},
    {"3.40282357e38", kInf},  // rounds past FLT_MAX
    {"1e99999999999999999999", kInf},
    {"1e-400", 0.0f},  // below the range: ±0
    {"-1e-400", -0.0f},
    {"0.0000000000000000000000000000000000000000000000001", 0.0f},
    {"0e99999999999999999999", 0.0f},
    {"inf", kInf},
    {"-inf", -kInf},
    {"+inf", kInf},
    {"Infinity", kInf},
    {"nan", kNan},
    {"NaN", kNan},
    {"-nan", -kNan},
    {"nan(123)", kNan},
    {"+-1", std::nullopt},
    {"-+1", std::nullopt},
    {"++1", std::nullopt},
    {"--1", std::nullopt},
    {"+", std::nullopt},
    {"-", std::nullopt},
    {".", std::nullopt},
    {"1.2.3", std::nullopt},
    {"1e", std::nullopt},
    {"1e+", std::nullopt},
    {"e5", std::nullopt},
    {"1e400x", std::nullopt},
    {"0x10", std::nullopt},
    {"1,5", std::nullopt},
    {"1_0", std::nullopt},
    {"1f", std::nullopt},
    {"1d5", std::nullopt},
    {"infin", std::nullopt},
    {"nanx", std::nullopt},
    {"x", std::nullopt},
};

TEST(TextGrammar, ParseNumber) {
    for (const NumberCase& c : kNumbers) {
        SCOPED_TRACE(c.token);
        float f = 0;
        double d = 0;
        EXPECT_EQ(io::parse_number(c.token, f), c.value.has_value());
        EXPECT_EQ(io::parse_number(c.token, d), c.value.has_value());
        if (c.value) {
            EXPECT_TRUE(same(f, *c.value)) << f;
        }
    }
    float f = 0;
    EXPECT_FALSE(io::parse_number("", f));
    double d = 0;
    ASSERT_TRUE(io::parse_number("1e400", d));
    EXPECT_EQ(d, std::numeric_limits<double>::infinity());
    ASSERT_TRUE(io::parse_number("-1e-400", d));
    EXPECT_TRUE(d == 0 && std::signbit(d));
    ASSERT_TRUE(io::parse_number("1e300", d));  // past float's range only
    EXPECT_EQ(d, 1e300);
    ASSERT_TRUE(io::parse_number("4e-320", d));  // a subnormal double
    EXPECT_EQ(d, 4e-320);
}

TEST(TextGrammar, ParseInteger) {
    int64_t i = 0;
    EXPECT_TRUE(io::parse_integer("+42", i) && i == 42);
    EXPECT_TRUE(io::parse_integer("-42", i) && i == -42);
    EXPECT_TRUE(io::parse_integer("007", i) && i == 7);
    EXPECT_TRUE(io::parse_integer("-9223372036854775808", i) && i == std::numeric_limits<int64_t>::min());
    EXPECT_TRUE(io::parse_integer("9223372036854775807", i) && i == std::numeric_limits<int64_t>::max());
    EXPECT_FALSE(io::parse_integer("9223372036854775808", i));
    EXPECT_FALSE(io::parse_integer("-9223372036854775809", i));
    for (const char* bad : {"", "+", "-", "+-1", "-+1", "++1", "1.0", "1.", "1e3", "0x10", "1,5", " 1", "1 ", "nan"}) {
        SCOPED_TRACE(bad);
        EXPECT_FALSE(io::parse_integer(bad, i));
    }
    uint64_t u = 0;
    EXPECT_TRUE(io::parse_integer("18446744073709551615", u) && u == ~uint64_t{0});
    EXPECT_FALSE(io::parse_integer("18446744073709551616", u));
    EXPECT_TRUE(io::parse_integer("+3", u) && u == 3);
    EXPECT_TRUE(io::parse_integer("-0", u) && u == 0);
    EXPECT_FALSE(io::parse_integer("-1", u));
    int8_t s8 = 0;
    EXPECT_TRUE(io::parse_integer("-128", s8) && s8 == -128);
    EXPECT_TRUE(io::parse_integer("127", s8) && s8 == 127);
    EXPECT_FALSE(io::parse_integer("128", s8));
    EXPECT_FALSE(io::parse_integer("-129", s8));
    uint8_t u8 = 0;
    EXPECT_TRUE(io::parse_integer("255", u8) && u8 == 255);
    EXPECT_FALSE(io::parse_integer("256", u8));
}

TEST(TextGrammar, Words) {
    std::string_view rest = " \tusemtl\v red \f\r\n";
    EXPECT_EQ(io::next_word(rest), "usemtl");
    EXPECT_EQ(io::next_word(rest), "red");
    EXPECT_EQ(io::next_word(rest), "");
    EXPECT_EQ(io::trim_blanks("\t a b \r\n"), "a b");
    EXPECT_EQ(io::trim_blanks(" \n "), "");
}

// One input per text format, with `token` where a number goes.
struct Format {
    const char* name;
    std::string (*file)(const TempDir& dir, const std::string& token);
    float (*value)(const std::string& path);  // the number as read
};

float first_x(const std::string& path) {
    test::Soup s = test::read_soup(path);
    EXPECT_EQ(s.triangles(), 1u);
    return s.xyz.empty() ? 0 : s.xyz[0];
}

std::string stl_file(const TempDir& dir, const std::string& token) {
    test::spit(dir / "t.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex " + token +
                                  " 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n");
    return dir / "t.stl";
}

std::string ply_file(const TempDir& dir, const std::string& token, const char* type) {
    test::spit(dir / "t.ply", std::string("ply\nformat ascii 1.0\nelement vertex 3\nproperty ") + type +
                                  " x\nproperty float y\nproperty float z\nelement face 1\n"
                                  "property list uchar int vertex_indices\nend_header\n" +
                                  token + " 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    return dir / "t.ply";
}

std::string obj_file(const TempDir& dir, const std::string& token) {
    test::spit(dir / "t.obj", "v " + token + " 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    return dir / "t.obj";
}

std::string mtl_file(const TempDir& dir, const std::string& token) {
    test::spit(dir / "t.mtl", "newmtl m\nKd " + token + " 0 0\n");
    test::spit(dir / "m.obj", "mtllib t.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    return dir / "m.obj";
}

float kd_red(const std::string& path) {
    test::Soup s = test::read_soup(path);
    EXPECT_EQ(s.header.materials.size(), 1u);
    return s.header.materials.empty() ? 0 : s.header.materials[0].base_color[0];
}

const Format kFormats[] = {
    {"stl-ascii", stl_file, first_x},
    {"ply-ascii float", [](const TempDir& d, const std::string& t) { return ply_file(d, t, "float"); }, first_x},
    {"obj", obj_file, first_x},
    {"mtl", mtl_file, kd_red},
};

class TextGrammarAcrossFormats : public testing::TestWithParam<NumberCase> {};

// Every format accepts the token with the same value, or refuses it in an error that names the
// file and line and quotes the token.
TEST_P(TextGrammarAcrossFormats, SameNumberOrSameRefusal) {
    const NumberCase& c = GetParam();
    TempDir dir;
    for (const Format& f : kFormats) {
        SCOPED_TRACE(f.name);
        const std::string path = f.file(dir, c.token);
        if (c.value) {
            try {
                const float v = f.value(path);
                EXPECT_TRUE(same(v, *c.value)) << v;
            } catch (const io::Error& e) {
                ADD_FAILURE() << e.what();
            }
        } else {
            const io::Error e = test::read_error(path);
            EXPECT_NE(e.message().find("found " + io::quote_token(c.token)), std::string::npos) << e.what();
            EXPECT_TRUE(e.file().ends_with(f.name == std::string("mtl") ? "t.mtl" : path)) << e.what();
            EXPECT_GT(e.line(), 0u) << e.what();
        }
    }
    // A double x in PLY takes the same tokens (its value then rounded to float).
    const std::string path = ply_file(dir, c.token, "double");
    if (c.value) {
        EXPECT_NO_THROW(first_x(path));
    } else {
        EXPECT_NE(test::read_error(path).message().find("found " + io::quote_token(c.token)), std::string::npos);
    }
}

INSTANTIATE_TEST_SUITE_P(Tokens, TextGrammarAcrossFormats, testing::ValuesIn(kNumbers),
                         [](const testing::TestParamInfo<NumberCase>& param) { return std::to_string(param.index); });

// Integers: an OBJ face index, and a PLY face index, list length and face count take the same
// tokens. Vertex k (0-based) is at x = k, so the first corner's x tells the index read.
TEST(TextGrammar, IntegersAcrossFormats) {
    const char* valid[] = {"3", "+3", "03", "+03"};  // all 3
    const char* invalid[] = {"+-3", "-+3", "++3", "+",  "3.0",   "3.",
                             "3e0", "0x3", "3,0", "3_", "three", "99999999999999999999"};
    TempDir dir;
    const std::string v = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\n";
    const std::string vertices =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
    const std::string faces = "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n";
    auto write = [&](const std::string& t) {
        test::spit(dir / "i.obj", v + "f " + t + " 4 2\n");                                      // OBJ's 3 is vertex 2
        test::spit(dir / "i.ply", vertices + "element face 1\n" + faces + "3 " + t + " 2 1\n");  // PLY's 3 is vertex 3
        test::spit(dir / "n.ply", vertices + "element face 1\n" + faces + t + " 3 2 1\n");
        test::spit(dir / "c.ply", vertices + "element face " + t + "\n" + faces + "3 3 2 1\n3 3 2 1\n3 3 2 1\n");
    };
    for (const char* token : valid) {
        SCOPED_TRACE(token);
        write(token);
        EXPECT_EQ(first_x(dir / "i.obj"), 2.0f);
        EXPECT_EQ(first_x(dir / "i.ply"), 3.0f);
        EXPECT_EQ(first_x(dir / "n.ply"), 3.0f);
        EXPECT_EQ(test::read_soup(dir / "c.ply").triangles(), 3u);
    }
    for (const char* token : invalid) {
        SCOPED_TRACE(token);
        write(token);
        const std::string quoted = "found " + io::quote_token(token);
        const io::Error obj = test::read_error(dir / "i.obj");
        EXPECT_NE(obj.message().find("expected a vertex index, " + quoted), std::string::npos) << obj.what();
        EXPECT_EQ(obj.line(), 5u);
        // "expected an integer" for a number that is none ("3.0"), "expected a number" for the rest.
        for (const char* name : {"i.ply", "n.ply"}) {
            const io::Error ply = test::read_error(dir / name);
            EXPECT_TRUE(ply.message().find("expected an integer, " + quoted) != std::string::npos ||
                        ply.message().find("expected a number, " + quoted) != std::string::npos)
                << ply.what();
            EXPECT_EQ(ply.line(), 14u) << ply.what();
        }
        EXPECT_NE(test::read_error(dir / "c.ply").message().find("bad element count"), std::string::npos);
    }
    write("3.0");
    EXPECT_NE(test::read_error(dir / "i.ply").message().find("expected an integer, found '3.0'"), std::string::npos);
    write("0x3");
    EXPECT_NE(test::read_error(dir / "n.ply").message().find("expected a number, found '0x3'"), std::string::npos);
}

// In an ascii PLY each value is read by its declared type: a float-typed index list takes
// numbers of integral value, an integer-typed property integers only.
TEST(TextGrammar, PlyValuesByDeclaredType) {
    TempDir dir;
    const std::string head =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n";
    test::spit(dir / "f.ply", head +
                                  "property list uchar float vertex_indices\nend_header\n"
                                  "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0.0 1e0 +2.\n");
    EXPECT_EQ(test::read_soup(dir / "f.ply").triangles(), 1u);
    test::spit(dir / "h.ply", head +
                                  "property list uchar float vertex_indices\nend_header\n"
                                  "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1.5 2\n");
    EXPECT_NE(test::read_error(dir / "h.ply").message().find("expected an integer, found '1.5'"), std::string::npos);
    test::spit(dir / "r.ply", head +
                                  "property list uchar int vertex_indices\nend_header\n"
                                  "0 0 0 255.0 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n");
    const io::Error e = test::read_error(dir / "r.ply");
    EXPECT_NE(e.message().find("expected an integer, found '255.0'"), std::string::npos) << e.what();
}

}  // namespace
