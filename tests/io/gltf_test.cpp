// glTF tests: the Khronos validator (a real client) must report 0 errors and 0 warnings on
// every .glb/.gltf written here, Draco or not; exact counts on real files (GLB, embedded and
// external buffers, Draco, KHR_mesh_quantization, strips and fans, instanced node trees);
// world-space node transforms with mirrored winding; clean refusals naming the file and the
// extension, mode or accessor; lossy and exact round trips; atomic .gltf + .bin output.
#include "io/gltf.hpp"

#include "io/error.hpp"
#include "io/format.hpp"
#include "render_util.hpp"
#include "web_test_util.hpp"

#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <sys/statvfs.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <thread>
#include <tuple>

using namespace web_test;
using nlohmann::json;
using Compression = meshstream::io::GltfSettings::Compression;

namespace {

// Runs tests/tools/validate_gltf.mjs; a missing node or validator fails the test (the set-up
// script installs both), it is never skipped.
json validate(const std::string& path) {
    std::string node = MESHSTREAM_NODE;
    EXPECT_TRUE(fs::exists(node)) << "node not found (" << node << "); run tools/bootstrap.sh";
    std::string out;
    int status = run(quote(node) + " " + quote(MESHSTREAM_VALIDATE_GLTF) + " " + quote(path) + " " +
                         quote(tools_modules_dir()) + " 2>&1",
                     &out);
    EXPECT_NE(status, 2) << "validator could not run: " << out;
    json report = json::parse(out, nullptr, false);
    EXPECT_FALSE(report.is_discarded()) << out;
    return report;
}

// 0 errors, 0 warnings, and no infos but `also` and those compression gives: the validator
// decodes neither Draco nor meshopt, so it reports the extension as unsupported and the
// compressed data's bufferView or buffer as unused.
void expect_valid_allowing(const std::string& path, const std::set<std::string>& also) {
    SCOPED_TRACE(path);
    json report = validate(path);
    if (report.is_discarded()) return;
    const json& issues = report["issues"];
    EXPECT_EQ(issues["numErrors"], 0) << issues.dump(2);
    EXPECT_EQ(issues["numWarnings"], 0) << issues.dump(2);
    for (const json& m : issues["messages"]) {
        std::string code = m["code"];
        EXPECT_TRUE(code == "UNSUPPORTED_EXTENSION" || code == "UNUSED_OBJECT" || also.count(code)) << m.dump();
    }
}

void expect_valid(const std::string& path) { expect_valid_allowing(path, {}); }

json glb_json(const std::string& path) {
    std::string bytes = slurp(path);
    EXPECT_GE(bytes.size(), 20u);
    EXPECT_EQ(bytes.substr(0, 4), "glTF");
    uint32_t len;
    std::memcpy(&len, bytes.data() + 12, 4);
    return json::parse(bytes.substr(20, len));
}

std::string error_of(const std::string& path) {
    try {
        read_soup(path);
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), path);
        return e.what();
    }
    ADD_FAILURE() << "no io::Error for " << path;
    return {};
}

TEST(GltfReader, ExactCountsOnRealFiles) {
    struct Case {
        const char* file;
        uint64_t triangles;
    } cases[] = {
        {"gltf/BoxTextured.glb", 12},
        {"gltf/BoxTextured_draco_transcoder.glb", 12},
        {"gltf/BoxTextured_embedded.gltf", 12},
        {"gltf/BoxTextured_external/BoxTextured.gltf", 12},
        {"gltf/elephant_draco_gltfpipeline.glb", 5558},
        {"gltf/elephant_gltfpack_quantized.glb", 5558},
        // 65311 triangles in 29 meshes; the default scene instances some of them: 110336.
        {"gltf/2CylinderEngine_draco/2CylinderEngine.gltf", 110336},
        {"gltf/primitive_modes/Mesh_PrimitiveMode_04.gltf", 2},
        {"gltf/primitive_modes/Mesh_PrimitiveMode_05.gltf", 2},
        {"gltf/primitive_modes/Mesh_PrimitiveMode_11.gltf", 2},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        io::MeshHeader h;
        Soup s = read_soup(fixture(c.file), io::TriangleChunk::kDefaultCapacity, &h);
        EXPECT_EQ(s.triangles(), c.triangles);
        EXPECT_EQ(h.triangle_count, c.triangles);
        for (float v : s.xyz) ASSERT_TRUE(std::isfinite(v));
    }
}

TEST(GltfReader, SameBoxWhateverTheContainer) {
    Soup glb = read_soup(fixture("gltf/BoxTextured.glb"));
    EXPECT_EQ(read_soup(fixture("gltf/BoxTextured_embedded.gltf")).xyz, glb.xyz);
    EXPECT_EQ(read_soup(fixture("gltf/BoxTextured_external/BoxTextured.gltf")).xyz, glb.xyz);
}

TEST(GltfReader, QuantizedAndDracoElephantsMatchTheSequentialDrc) {
    // Three encodings of CGAL's elephant: same triangle count and (to quantization) same box.
    auto box = [](const Soup& s) {
        std::array<float, 6> b = {1e30f, 1e30f, 1e30f, -1e30f, -1e30f, -1e30f};
        for (size_t i = 0; i < s.xyz.size(); i += 3)
            for (int a = 0; a < 3; ++a) {
                b[a] = std::min(b[a], s.xyz[i + a]);
                b[3 + a] = std::max(b[3 + a], s.xyz[i + a]);
            }
        return b;
    };
    auto ref = box(read_soup(fixture("drc/elephant_normals_sequential_cl0.drc")));
    for (const char* f : {"gltf/elephant_gltfpack_quantized.glb", "gltf/elephant_draco_gltfpipeline.glb"}) {
        auto b = box(read_soup(fixture(f)));
        for (int i = 0; i < 6; ++i) EXPECT_NEAR(b[i], ref[i], 2e-3) << f << " bbox " << i;
    }
}

TEST(GltfReader, StripsAndFansKeepOneWinding) {
    for (const char* f :
         {"gltf/primitive_modes/Mesh_PrimitiveMode_04.gltf", "gltf/primitive_modes/Mesh_PrimitiveMode_05.gltf",
          "gltf/primitive_modes/Mesh_PrimitiveMode_11.gltf"}) {
        Soup s = read_soup(fixture(f));
        ASSERT_EQ(s.triangles(), 2u) << f;
        double nz[2];
        for (int t = 0; t < 2; ++t) {
            const float* p = &s.xyz[9 * t];
            nz[t] = (double(p[3]) - p[0]) * (double(p[7]) - p[1]) - (double(p[4]) - p[1]) * (double(p[6]) - p[0]);
        }
        EXPECT_GT(nz[0] * nz[1], 0) << f << ": the two triangles face opposite ways";
    }
}

TEST(GltfReader, ChunkBoundariesGiveIdenticalSoup) {
    const std::string f = fixture("gltf/2CylinderEngine_draco/2CylinderEngine.gltf");
    Soup whole = read_soup(f);
    for (size_t cap : {size_t{1}, size_t{7}}) EXPECT_EQ(read_soup(f, cap).xyz, whole.xyz) << cap;
}

// ---------------------------------------------------------------- EXT_meshopt_compression

// The JSON and BIN chunks of a GLB file.
std::pair<json, std::string> glb_parts(const std::string& path) {
    const std::string bytes = slurp(path);
    uint32_t json_len, bin_len;
    std::memcpy(&json_len, bytes.data() + 12, 4);
    std::memcpy(&bin_len, bytes.data() + 20 + json_len, 4);
    return {json::parse(bytes.substr(20, json_len)), bytes.substr(28 + json_len, bin_len)};
}

// A GLB of `doc` and `bin`, padded as GLB requires. Returns the BIN chunk data's file offset.
uint64_t write_glb(const std::string& path, const json& doc, std::string bin) {
    std::string text = doc.dump();
    while (text.size() % 4) text.push_back(' ');
    while (bin.size() % 4) bin.push_back('\0');
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    const uint32_t total = static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size());
    std::ofstream(path, std::ios::binary) << "glTF" << u32(2) << u32(total) << u32(uint32_t(text.size())) << "JSON"
                                          << text << u32(uint32_t(bin.size())) << "BIN" << std::string(1, '\0') << bin;
    return 28 + text.size();
}

// A soup's triangles, each rotated to start at its smallest corner, sorted: equal for two
// soups holding the same triangles (same orientation) in any order.
std::vector<std::array<float, 9>> triangle_multiset(const Soup& s) {
    std::vector<std::array<float, 9>> out(s.triangles());
    for (size_t t = 0; t < s.triangles(); ++t) {
        const float* p = &s.xyz[9 * t];
        int best = 0;
        for (int c = 1; c < 3; ++c)
            if (std::lexicographical_compare(p + 3 * c, p + 3 * c + 3, p + 3 * best, p + 3 * best + 3)) best = c;
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) out[t][3 * c + a] = p[3 * ((best + c) % 3) + a];
    }
    std::sort(out.begin(), out.end());
    return out;
}

TEST(GltfMeshopt, ElephantMatchesItsUncompressedTwinExactly) {
    // gltfpack 0.18 wrote the same 14-bit quantized elephant twice, plain and with -cc (which
    // also reorders the triangles for its strip coder): decoded, the two hold the same
    // triangles, float for float.
    io::MeshHeader h;
    Soup packed = read_soup(fixture("gltf/elephant_meshopt.glb"), 1000, &h);
    Soup plain = read_soup(fixture("gltf/elephant_gltfpack_quantized.glb"));
    ASSERT_EQ(packed.triangles(), 5558u);
    EXPECT_EQ(h.triangle_count, 5558u);
    EXPECT_EQ(triangle_multiset(packed), triangle_multiset(plain));
    EXPECT_NE(packed.xyz, plain.xyz) << "the strip order differs: the test would not see a reordering bug";
    // Every coordinate is translation + q · scale of the node, q an integer of 14 bits.
    const double translation[3] = {-0.360217005, -0.5, -0.301481009}, scale = 6.10388815e-05;
    for (size_t i = 0; i < packed.xyz.size(); ++i) {
        const double q = (packed.xyz[i] - translation[i % 3]) / scale;
        ASSERT_NEAR(q, std::round(q), 1e-2) << i;
        ASSERT_GE(std::round(q), 0);
        ASSERT_LE(std::round(q), 16383);
    }
    bool noted = false;
    for (const auto& [k, v] : h.notes)
        if (k == "meshopt") noted = v == "1 ATTRIBUTES, 1 TRIANGLES buffer view(s), 18 KiB compressed, 54 KiB decoded";
    EXPECT_TRUE(noted) << "info reports the compressed views";
}

TEST(GltfMeshopt, GltfpackBoxWithOctahedralNormalsHasTheBoxsPositions) {
    // gltfpack -cc of BoxTextured.glb: an OCTAHEDRAL-filtered normal view, quantized positions
    // and texture coordinates. Its 12 triangles are the box's (the node's rotation baked in),
    // each corner within half a 14-bit step of the unit cube's extent.
    Soup packed = read_soup(fixture("gltf/BoxTextured_gltfpack_cc.glb"));
    Soup box = read_soup(fixture("gltf/BoxTextured.glb"));
    ASSERT_EQ(packed.triangles(), 12u);
    const auto a = triangle_multiset(packed), b = triangle_multiset(box);
    for (size_t t = 0; t < a.size(); ++t)
        for (int i = 0; i < 9; ++i) EXPECT_NEAR(a[t][i], b[t][i], 0.5 / 16383 + 1e-6) << t << " " << i;
}

TEST(GltfMeshopt, ExponentialFilterAndIndexSequence) {
    // Float positions through the EXPONENTIAL filter (23-bit mantissas) and indices coded as a
    // sequence (mode INDICES), written here with libmeshoptimizer's encoders.
    TempDir dir;
    const float quad[12] = {0.25f, -3.5f, 1e-3f, 1000.5f, -3.5f, 1e-3f, 1000.5f, 2.75f, 1e-3f, 0.25f, 2.75f, 7.0f};
    uint32_t exp[12];
    meshopt_encodeFilterExp(exp, 4, 12, 23, quad);
    std::vector<unsigned char> vbuf(meshopt_encodeVertexBufferBound(4, 12));
    vbuf.resize(meshopt_encodeVertexBuffer(vbuf.data(), vbuf.size(), exp, 4, 12));
    const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    std::vector<unsigned char> ibuf(meshopt_encodeIndexSequenceBound(6, 4));
    ibuf.resize(meshopt_encodeIndexSequence(ibuf.data(), ibuf.size(), indices, 6));
    std::string bin(vbuf.begin(), vbuf.end());
    while (bin.size() % 4) bin.push_back('\0');
    const size_t ioffset = bin.size();
    bin.append(ibuf.begin(), ibuf.end());
    json doc = {
        {"asset", {{"version", "2.0"}}},
        {"extensionsUsed", {"EXT_meshopt_compression"}},
        {"extensionsRequired", {"EXT_meshopt_compression"}},
        {"buffers",
         {{{"byteLength", bin.size()}},
          {{"byteLength", 72}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}}},
        {"bufferViews",
         {{{"buffer", 1},
           {"byteLength", 48},
           {"byteStride", 12},
           {"extensions",
            {{"EXT_meshopt_compression",
              {{"buffer", 0},
               {"byteLength", vbuf.size()},
               {"byteStride", 12},
               {"count", 4},
               {"mode", "ATTRIBUTES"},
               {"filter", "EXPONENTIAL"}}}}}},
          {{"buffer", 1},
           {"byteOffset", 48},
           {"byteLength", 24},
           {"extensions",
            {{"EXT_meshopt_compression",
              {{"buffer", 0},
               {"byteOffset", ioffset},
               {"byteLength", ibuf.size()},
               {"byteStride", 4},
               {"count", 6},
               {"mode", "INDICES"}}}}}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
          {{"bufferView", 1}, {"componentType", 5125}, {"count", 6}, {"type", "SCALAR"}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
        {"nodes", {{{"mesh", 0}}}},
    };
    write_glb(dir / "exp.glb", doc, bin);
    Soup s = read_soup(dir / "exp.glb");
    ASSERT_EQ(s.triangles(), 2u);
    for (int t = 0; t < 2; ++t)
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) {
                // One exponent per vertex (its largest component's): 23 bits relative to that.
                const float* v = &quad[3 * indices[3 * t + k]];
                const float largest = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
                EXPECT_NEAR(s.xyz[9 * t + 3 * k + a], v[a], largest * 2.4e-7) << t << k << a;
            }
}

TEST(GltfMeshopt, BadParametersAreErrorsNamingTheView) {
    // Each edit of elephant_meshopt.glb's JSON is refused before libmeshoptimizer sees it (its
    // decoders assert on what is refused here) or when it reports a failure, with the
    // bufferView named; a cut stream is also placed in the file.
    TempDir dir;
    const auto [doc, bin] = glb_parts(fixture("gltf/elephant_meshopt.glb"));
    struct Case {
        std::function<void(json&)> edit;
        std::string expected;
        uint64_t byte = 0;
    };
    const std::string pos = "mesh 0 primitive 0 POSITION (accessor 0): bufferView 0 (EXT_meshopt_compression)";
    const std::string idx = "mesh 0 primitive 0 indices (accessor 1): bufferView 1 (EXT_meshopt_compression)";
    auto ext = [](json& d, int view) -> json& {
        return d["bufferViews"][view]["extensions"]["EXT_meshopt_compression"];
    };
    const Case cases[] = {
        {[&](json& d) { ext(d, 1)["byteLength"] = 100; },
         idx + ": the compressed index data is corrupt or cut short (100 bytes for 16674 indices of 2 bytes; "
               "libmeshoptimizer's meshopt_decodeIndexBuffer returned -2)",
         11568},
        {[&](json& d) { ext(d, 0)["byteLength"] = 3000; },
         pos + ": the compressed vertex data is corrupt or cut short (3000 bytes for 2775 elements of 8 bytes; "
               "libmeshoptimizer's meshopt_decodeVertexBuffer returned -2)",
         0},
        {[&](json& d) { ext(d, 0)["count"] = 2774; },
         pos + " decodes to count 2774 x byteStride 8 bytes, but its bufferView's byteLength is 22200"},
        {[&](json& d) { ext(d, 1)["mode"] = "STRIPS"; },
         idx + " has mode 'STRIPS' (one of ATTRIBUTES, TRIANGLES, INDICES)"},
        {[&](json& d) { ext(d, 1)["byteStride"] = 8; }, idx + ": TRIANGLES with byteStride 8 (must be 2 or 4)"},
        {[&](json& d) { ext(d, 1)["count"] = 16673; }, idx + ": TRIANGLES with count 16673, not a multiple of 3"},
        {[&](json& d) { ext(d, 1)["filter"] = "OCTAHEDRAL"; },
         idx + ": filter OCTAHEDRAL with mode TRIANGLES (filters apply to ATTRIBUTES only)"},
        {[&](json& d) { ext(d, 0)["filter"] = "SHARPEN"; },
         pos + " has filter 'SHARPEN' (one of NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL)"},
        {[&](json& d) { ext(d, 0)["byteStride"] = 6; },
         pos + ": ATTRIBUTES with byteStride 6 (must be a multiple of 4, 4-256)"},
        {[&](json& d) { ext(d, 0)["byteStride"] = 12, ext(d, 0)["filter"] = "OCTAHEDRAL"; },
         pos + ": filter OCTAHEDRAL with byteStride 12 (must be 4 or 8)"},
        {[&](json& d) { ext(d, 0)["byteStride"] = 4, ext(d, 0)["filter"] = "QUATERNION"; },
         pos + ": filter QUATERNION with byteStride 4 (must be 8)"},
        {[&](json& d) { d["bufferViews"][0]["byteStride"] = 12; }, pos + " has byteStride 8, its bufferView 12"},
        {[&](json& d) { ext(d, 0)["byteOffset"] = 20000; },
         pos + ": compressed bytes 20000 to 31565 lie outside buffer 0 (18040 bytes)"},
        {[&](json& d) { ext(d, 0)["buffer"] = 1; }, pos + " refers to buffer 1, a fallback buffer without data"},
        {[&](json& d) { ext(d, 0).erase("count"); }, pos + " needs 'count' as a non-negative integer"},
        {[&](json& d) { d["bufferViews"][1].erase("extensions"); },
         "mesh 0 primitive 0 indices (accessor 1): bufferView 1 lies in buffer 1, an EXT_meshopt_compression fallback "
         "buffer without data"},
    };
    for (const Case& c : cases) {
        json edited = doc;
        c.edit(edited);
        const uint64_t offset = write_glb(dir / "bad.glb", edited, bin);
        try {
            read_soup(dir / "bad.glb");
            ADD_FAILURE() << "accepted: " << c.expected;
        } catch (const io::Error& e) {
            EXPECT_EQ(e.file(), dir / "bad.glb");
            EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
            if (c.expected.find("corrupt") != std::string::npos) {
                EXPECT_EQ(e.byte_offset(), offset + c.byte) << e.what();
            }
        }
    }
}

TEST(GltfMeshopt, CutOrCorruptStreamsAreErrorsOrReadNeverCrashes) {
    // The file cut at every length is an error; seeded byte flips in the compressed streams
    // either decode (to other, still bounds-checked, data) or are an error. Under the ASan
    // suite this also checks that nothing is read or written out of bounds.
    TempDir dir;
    const std::string bytes = slurp(fixture("gltf/elephant_meshopt.glb"));
    for (size_t n = 1; n < bytes.size(); n += (n < 64 ? 1 : 191)) {
        std::ofstream(dir / "t.glb", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(n));
        EXPECT_THROW(read_soup(dir / "t.glb"), io::Error) << "cut to " << n;
    }
    const auto [doc, bin] = glb_parts(fixture("gltf/elephant_meshopt.glb"));
    std::mt19937 rng(21);
    int errors = 0, reads = 0;
    for (int round = 0; round < 100; ++round) {
        std::string corrupt = bin;
        for (int k = 0; k < 4; ++k) corrupt[rng() % 18038] ^= static_cast<char>(1 + rng() % 255);
        write_glb(dir / "c.glb", doc, corrupt);
        try {
            read_soup(dir / "c.glb");
            ++reads;
        } catch (const io::Error&) {
            ++errors;
        }
    }
    EXPECT_EQ(errors + reads, 100);
    EXPECT_GT(errors, 0) << "some corruption must be caught (an index past the vertices, a bad header)";
}

// A one-triangle document with an external buffer, for transform and refusal cases.
struct HandMade {
    TempDir dir;
    std::string path = dir / "hand.gltf";
    explicit HandMade(const std::string& extra_top, const std::string& mode = "4",
                      const std::string& nodes = R"([{"mesh":0}])", const std::string& scene_nodes = "[0]",
                      int position_count = 3) {
        const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        std::ofstream(dir / "hand.bin", std::ios::binary).write(reinterpret_cast<const char*>(tri), sizeof tri);
        std::ofstream(path) << R"({"asset":{"version":"2.0"},)" << extra_top
                            << R"("buffers":[{"uri":"hand.bin","byteLength":36}],)"
                            << R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                            << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << position_count
                            << R"(,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
                            << R"("meshes":[{"name":"tri","primitives":[{"attributes":{"POSITION":0},"mode":)" << mode
                            << "}]}],"
                            << R"("nodes":)" << nodes << R"(,"scenes":[{"nodes":)" << scene_nodes << R"(}],"scene":0})";
    }
};

TEST(GltfReader, AppliesNodeTransformsAndFlipsMirroredWinding) {
    // Node 0 translates by +10 in x and holds node 1, which mirrors x and instances the mesh;
    // node 2 instances it again untransformed.
    HandMade doc(
        "", "4",
        R"([{"translation":[10,0,0],"children":[1]},{"scale":[-1,1,1],"mesh":0},{"mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}])",
        "[0,2]");
    io::MeshHeader h;
    Soup s = read_soup(doc.path, 16, &h);
    ASSERT_EQ(s.triangles(), 2u);
    EXPECT_EQ(h.triangle_count, 2u);
    // Mirrored: (10,0,0) (9,0,0) (10,1,0), corners 1 and 2 swapped to keep it facing +z.
    const std::vector<float> mirrored = {10, 0, 0, 10, 1, 0, 9, 0, 0};
    const std::vector<float> plain = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    EXPECT_EQ(std::vector<float>(s.xyz.begin(), s.xyz.begin() + 9), mirrored);
    EXPECT_EQ(std::vector<float>(s.xyz.begin() + 9, s.xyz.end()), plain);
}

TEST(GltfReader, SkinnedMeshIgnoresItsNodeTransform) {
    // glTF 2.0: "only the joint transforms are applied to the skinned mesh; the transform of
    // the skinned mesh node MUST be ignored". Node 1 is the (untransformed) joint.
    HandMade doc(R"("skins":[{"joints":[1]}],)", "4", R"([{"mesh":0,"skin":0,"translation":[100,0,0]},{}])", "[0,1]");
    Soup s = read_soup(doc.path);
    EXPECT_EQ(s.xyz, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
}

TEST(GltfReader, RefusesPointsAndLinesNamingMeshAndPrimitive) {
    HandMade points("", "0");
    std::string what = error_of(points.path);
    EXPECT_NE(what.find("mesh 0 'tri' primitive 0 has mode POINTS"), std::string::npos) << what;
    HandMade lines("", "1");
    what = error_of(lines.path);
    EXPECT_NE(what.find("has mode LINES"), std::string::npos) << what;
}

TEST(GltfReader, RefusesUnknownRequiredExtensionByName) {
    HandMade doc(R"("extensionsUsed":["EXT_made_up"],"extensionsRequired":["EXT_made_up"],)");
    std::string what = error_of(doc.path);
    EXPECT_NE(what.find("requires extension EXT_made_up"), std::string::npos) << what;
}

TEST(GltfReader, RefusesAccessorsOutsideTheirBufferView) {
    HandMade doc("", "4", R"([{"mesh":0}])", "[0]", 6);  // 6 positions promised, 3 stored
    std::string what = error_of(doc.path);
    EXPECT_NE(what.find("mesh 0 'tri' primitive 0 POSITION (accessor 0) reaches byte 72"), std::string::npos) << what;
}

TEST(GltfReader, AppliesMorphTargetsAtTheirDefaultWeights) {
    // A viewer shows base + Σ weight·target; the mesh's weights are the default, a node's
    // replace them. The targets used to be ignored (z = 0 below, with no word said).
    TempDir dir;
    const float data[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 5, 0, 0, 5, 2, 0, 5};
    std::ofstream(dir / "m.bin", std::ios::binary).write(reinterpret_cast<const char*>(data), sizeof data);
    auto write = [&](const std::string& nodes) {
        std::ofstream(dir / "m.gltf")
            << R"({"asset":{"version":"2.0"},"buffers":[{"uri":"m.bin","byteLength":72}],)"
            << R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":36}],)"
            << R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
            << R"({"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}],)"
            << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"targets":[{"POSITION":1}]}],"weights":[1.0]}],)"
            << R"("nodes":)" << nodes << R"(,"scenes":[{"nodes":[0]}],"scene":0})";
    };
    write(R"([{"mesh":0}])");
    EXPECT_EQ(read_soup(dir / "m.gltf").xyz, (std::vector<float>{0, 0, 5, 1, 0, 5, 2, 1, 5}));
    write(R"([{"mesh":0,"weights":[0.5],"translation":[0,0,1]}])");
    EXPECT_EQ(read_soup(dir / "m.gltf").xyz, (std::vector<float>{0, 0, 3.5, 1, 0, 3.5, 1, 1, 3.5}));
    write(R"([{"mesh":0,"weights":[0]}])");
    EXPECT_EQ(read_soup(dir / "m.gltf").xyz, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));

    // Draco reorders vertices, so a target cannot be matched to them: refused by name.
    const std::string engine = fixture("gltf/2CylinderEngine_draco/2CylinderEngine");
    std::filesystem::copy_file(engine + ".bin", dir / "2CylinderEngine.bin");
    json doc = json::parse(slurp(engine + ".gltf"));
    json& prim = doc["meshes"][0]["primitives"][0];
    prim["targets"] = json::array({{{"POSITION", prim["attributes"]["POSITION"]}}});
    doc["meshes"][0]["weights"] = json::array({0.25});
    std::ofstream(dir / "engine.gltf") << doc.dump();
    const std::string what = error_of(dir / "engine.gltf");
    EXPECT_NE(what.find("primitive 0 morph target 0 has weight 0.25: morph targets of KHR_draco_mesh_compression "
                        "primitives are not supported"),
              std::string::npos)
        << what;
}

// tinygltf quotes what it could not read: a broken 100 kB data URI came back whole, raw bytes
// and all. The message is cut and its bytes made printable.
TEST(GltfReader, TinygltfMessagesAreCutAndPrintable) {
    TempDir dir;
    const std::string head =
        R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)";
    std::ofstream(dir / "long.gltf") << head << std::string(100000, '!') << R"("}]})";
    const std::string long_error = error_of(dir / "long.gltf");
    EXPECT_NE(long_error.find("invalid glTF: Failed to decode 'uri'"), std::string::npos) << long_error.substr(0, 300);
    EXPECT_LT(long_error.size(), 1000u);
    std::ofstream(dir / "raw.gltf") << head << std::string(10, '\xff') << R"("}]})";
    const std::string raw_error = error_of(dir / "raw.gltf");
    EXPECT_EQ(raw_error.find('\xff'), std::string::npos) << raw_error;
    EXPECT_NE(raw_error.find("\\xff"), std::string::npos) << raw_error;
}

TEST(GltfReader, BufferFilesCountAgainstTheMemoryBudget) {
    // The document (3 695 bytes) was held to --memory, its buffer files (840 bytes here, 18 MB
    // for a 1 M mesh) were not.
    const std::string path = fixture("gltf/BoxTextured_external/BoxTextured.gltf");
    io::ReadOptions options;
    options.memory_budget_bytes = 4000;
    std::string what;
    try {
        io::open_input(path, {}, options);
    } catch (const io::Error& e) {
        what = e.what();
    }
    EXPECT_NE(what.find("glTF documents are read whole into memory with their buffers: this one and its buffer files "
                        "take 4.4 KiB, over the memory budget of 3.9 KiB; raise the memory budget"),
              std::string::npos)
        << what;
    options.memory_budget_bytes = 3695 + 840;
    EXPECT_EQ(io::open_input(path, {}, options).reader->triangle_count(), 12u);
}

TEST(GltfReader, NamesABufferViewPastTheEndOfItsBuffer) {
    // The message used to clamp the view's end to the buffer: "reaches byte 36 of a buffer view
    // ending at 36".
    TempDir dir;
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::ofstream(dir / "v.bin", std::ios::binary).write(reinterpret_cast<const char*>(tri), sizeof tri);
    std::ofstream(dir / "v.gltf")
        << R"({"asset":{"version":"2.0"},"buffers":[{"uri":"v.bin","byteLength":36}],)"
        << R"("bufferViews":[{"buffer":0,"byteLength":400}],)"
        << R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
        << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}]})";
    std::string what = error_of(dir / "v.gltf");
    EXPECT_NE(what.find("bufferView 0 ends at byte 400, past the end of buffer 0 (36 bytes)"), std::string::npos)
        << what;
}

TEST(GltfReader, RefusesAByteStrideSmallerThanTheElement) {
    // byteStride 4 under VEC3 floats read overlapping elements: a cube gave 10 triangles of
    // garbage, exit 0. A stride wider than the element (interleaved data) is read.
    TempDir dir;
    const float padded[12] = {0, 0, 0, 9, 1, 0, 0, 9, 0, 1, 0, 9};  // x y z and a fourth float
    std::ofstream(dir / "s.bin", std::ios::binary).write(reinterpret_cast<const char*>(padded), sizeof padded);
    auto write =
        [&](int stride) {
            std::ofstream(dir / "s.gltf")
                << R"({"asset":{"version":"2.0"},"buffers":[{"uri":"s.bin","byteLength":48}],)"
                << R"("bufferViews":[{"buffer":0,"byteLength":48,"byteStride":)" << stride << "}],"
                << R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
                << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}]})";
        };
    write(16);
    EXPECT_EQ(read_soup(dir / "s.gltf").xyz, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
    for (int stride : {4, 8}) {
        write(stride);
        std::string what = error_of(dir / "s.gltf");
        EXPECT_NE(what.find("mesh 0 primitive 0 POSITION (accessor 0): bufferView 0 has byteStride " +
                            std::to_string(stride) + ", less than the accessor's 12-byte elements"),
                  std::string::npos)
            << what;
    }
}

TEST(GltfReader, OffsetsAndCountsNearTwoToThe64AreRefusedNotWrapped) {
    // Sums and products of these 64-bit numbers wrapped: a view 4 bytes before its buffer, an
    // accessor 8 bytes before its view, 2^60 + 1 elements 16 bytes apart "ending" at byte 12,
    // all read or allocated as if in bounds (exit 0, or std::length_error); an accessor without
    // a bufferView of 2^64 / 3 + 1 zeros wrote past a vector of 2 floats (SIGSEGV).
    TempDir dir;
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::ofstream(dir / "o.bin", std::ios::binary).write(reinterpret_cast<const char*>(tri), sizeof tri);
    struct Case {
        const char* view;
        const char* accessor;
        const char* expected;
    } cases[] = {
        {R"({"buffer":0,"byteOffset":18446744073709551612,"byteLength":40})", R"("bufferView":0,"count":3)",
         "POSITION (accessor 0): bufferView 0 ends at byte 18446744073709551612 + 40, past the end of buffer 0 (36 "
         "bytes)"},
        {R"({"buffer":0,"byteLength":36})", R"("bufferView":0,"byteOffset":18446744073709551608,"count":3)",
         "POSITION (accessor 0) reaches byte 2^64 or more of a buffer view ending at 36"},
        {R"({"buffer":0,"byteLength":36,"byteStride":16})", R"("bufferView":0,"count":1152921504606846977)",
         "POSITION (accessor 0) reaches byte 2^64 or more of a buffer view ending at 36"},
        {R"({"buffer":0,"byteLength":36})", R"("count":6148914691236517206)",
         "POSITION (accessor 0) has no bufferView (all zeros) and count 6148914691236517206, over the memory budget of "
         "256 MiB once decoded; raise the memory budget"},
        {R"({"buffer":0,"byteLength":36})", R"("count":300000000)",  // 3.6 GB of floats from 300 bytes
         "has no bufferView (all zeros) and count 300000000, over the memory budget"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.accessor);
        std::ofstream(dir / "o.gltf") << R"({"asset":{"version":"2.0"},"buffers":[{"uri":"o.bin","byteLength":36}],)"
                                      << R"("bufferViews":[)" << c.view << "],"
                                      << R"("accessors":[{"componentType":5126,"type":"VEC3",)" << c.accessor << "}],"
                                      << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":6}]}],)"
                                      << R"("nodes":[{"mesh":0}]})";
        std::string what = error_of(dir / "o.gltf");
        EXPECT_NE(what.find(c.expected), std::string::npos) << what;
    }
    // The same view in front of a Draco primitive's blob.
    const std::string engine = fixture("gltf/2CylinderEngine_draco/2CylinderEngine");
    std::filesystem::copy_file(engine + ".bin", dir / "2CylinderEngine.bin");
    json doc = json::parse(slurp(engine + ".gltf"));
    const int blob = doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"];
    doc["bufferViews"][blob]["byteOffset"] = uint64_t{18446744073709551612u};
    doc["bufferViews"][blob]["byteLength"] = 40;
    std::ofstream(dir / "engine.gltf") << doc.dump();
    const std::string what = error_of(dir / "engine.gltf");
    EXPECT_NE(what.find("KHR_draco_mesh_compression bufferView " + std::to_string(blob) + " lies outside its buffer"),
              std::string::npos)
        << what;
}

TEST(GltfReader, MissingBufferFileIsNotLookedUpInTheCurrentDirectory) {
    // tinygltf tries the current directory after the document's: with sub/a.bin gone and an
    // a.bin in the working directory, that one was read, silently.
    HandMade doc("");
    TempDir elsewhere;
    fs::rename(doc.dir / "hand.bin", elsewhere / "hand.bin");
    const fs::path was = fs::current_path();
    fs::current_path(elsewhere.path());
    const std::string relative = fs::relative(doc.path).string();  // ../meshstream-web-XXXXXX/hand.gltf
    std::string what[2];
    for (int i = 0; i < 2; ++i) {
        try {
            read_soup(i ? relative : doc.path);
        } catch (const io::Error& e) {
            what[i] = e.what();
        }
    }
    fs::current_path(was);
    EXPECT_EQ(what[0], doc.path + ": buffer file " + doc.dir / "hand.bin" +
                           " does not exist (buffer files are read from the document's directory only)");
    EXPECT_EQ(what[1], relative + ": buffer file " + fs::path(relative).parent_path().string() +
                           "/hand.bin does not exist (buffer files are read from the document's directory only)");
    // Beside the document it is found, also when the document is named without a directory.
    fs::rename(elsewhere / "hand.bin", doc.dir / "hand.bin");
    fs::current_path(doc.dir.path());
    const size_t triangles = read_soup("hand.gltf").triangles();
    fs::current_path(was);
    EXPECT_EQ(triangles, 1u);
}

// A GLB of `json` alone (no BIN chunk), padded as GLB requires.
std::string glb_of(std::string json) {
    while (json.size() % 4) json.push_back(' ');
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    return "glTF" + u32(2) + u32(static_cast<uint32_t>(20 + json.size())) + u32(static_cast<uint32_t>(json.size())) +
           "JSON" + json;
}

TEST(GltfReader, RefusesJsonNestedTooDeepBeforeParsingIt) {
    // 15 000 nested arrays (or 20 000 objects) in extras overflowed the stack inside tinygltf:
    // SIGSEGV. The 512th level is refused at its byte, in a .gltf and in a GLB's JSON chunk.
    TempDir dir;
    const std::string arrays = std::string(15000, '[') + std::string(15000, ']');
    std::string objects;
    for (int i = 0; i < 20000; ++i) objects += R"({"a":)";
    objects += "1" + std::string(20000, '}');
    for (const std::string& deep : {arrays, objects}) {
        HandMade doc(R"("extras":)" + deep + ",");
        const size_t first = slurp(doc.path).find(deep.substr(0, 1), 10);  // after asset's '{'
        std::string what = error_of(doc.path);
        EXPECT_NE(what.find(": byte " + std::to_string(first + (deep[0] == '[' ? 511 : 5 * 511)) +
                            ": JSON nested deeper than 512 arrays and objects"),
                  std::string::npos)
            << what.substr(0, 300);
        const std::string json = R"({"asset":{"version":"2.0"},"extras":)" + deep + "}";
        std::ofstream(dir / "deep.glb", std::ios::binary) << glb_of(json);
        what = error_of(dir / "deep.glb");
        EXPECT_NE(what.find(": byte " +
                            std::to_string(20 + json.find(deep.substr(0, 1), 10) + (deep[0] == '[' ? 511 : 5 * 511)) +
                            ": JSON nested deeper than 512"),
                  std::string::npos)
            << what.substr(0, 300);
    }
    // Brackets in strings, escaped quotes among them, do not count; 100 real levels are fine.
    const std::string in_strings = R"("\"[[[)" + std::string(1000, '{') + R"(\\",)";
    HandMade fine(R"("extras":[)" + in_strings + std::string(100, '[') + std::string(100, ']') + "],");
    EXPECT_EQ(read_soup(fine.path).triangles(), 1u);
}

TEST(GltfReader, RefusesTruncatedGlbAtEveryLength) {
    TempDir dir;
    std::string bytes = slurp(fixture("gltf/BoxTextured_draco_transcoder.glb"));
    // From the first byte: "g" alone was read as an empty OBJ (see BadInput.TruncationAtEvery…).
    for (size_t n = 1; n < bytes.size(); n += (n < 64 ? 1 : 61)) {
        std::ofstream(dir / "t.glb", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(n));
        EXPECT_THROW(read_soup(dir / "t.glb"), io::Error) << "truncated to " << n;
    }
    std::ofstream(dir / "t.glb", std::ios::binary).write(bytes.data(), 1);
    std::string what = error_of(dir / "t.glb");
    EXPECT_NE(what.find("t.glb: byte 1: file ends inside the 12-byte GLB header"), std::string::npos) << what;
    std::ofstream(dir / "t.glb", std::ios::binary).write(bytes.data(), 3968);
    what = error_of(dir / "t.glb");
    EXPECT_NE(what.find("byte 8: GLB header states 3976 bytes, the file holds 3968"), std::string::npos) << what;
}

TEST(GltfWriter, DracoGlbIsValidAndWithinQuantizationBound) {
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    write_soup(bunny, dir / "b.glb");
    expect_valid(dir / "b.glb");
    json doc = glb_json(dir / "b.glb");
    EXPECT_EQ(doc["asset"]["generator"].get<std::string>().rfind("meshstream ", 0), 0u);
    EXPECT_EQ(doc["extensionsRequired"], json::array({"KHR_draco_mesh_compression"}));
    EXPECT_EQ(doc["extensionsUsed"], json::array({"KHR_draco_mesh_compression"}));
    const json& prim = doc["meshes"][0]["primitives"][0];
    EXPECT_TRUE(prim["extensions"]["KHR_draco_mesh_compression"].contains("bufferView"));
    for (const json& a : doc["accessors"]) EXPECT_FALSE(a.contains("bufferView")) << a.dump();
    EXPECT_EQ(doc["accessors"][prim["indices"].get<int>()]["count"], 3 * 69451);
    EXPECT_EQ(doc["accessors"][prim["indices"].get<int>()]["componentType"], 5123);  // 34834 vertices
    io::MeshHeader h;
    Soup back = read_soup(dir / "b.glb", io::TriangleChunk::kDefaultCapacity, &h);
    expect_within_quantization_bound(bunny, back, 14);
    bool noted = false;
    for (const auto& [k, v] : h.notes)
        if (k == "draco")
            noted = v == "bitstream 2.2, edgebreaker connectivity, positions 14 bits (mesh 0 primitive 0)";
    EXPECT_TRUE(noted) << "info must report the Draco settings found";
    // POSITION min/max are the decoded bounds, exactly.
    const json& pos = doc["accessors"][prim["attributes"]["POSITION"].get<int>()];
    for (int a = 0; a < 3; ++a) {
        float lo = 1e30f, hi = -1e30f;
        for (size_t i = a; i < back.xyz.size(); i += 3) lo = std::min(lo, back.xyz[i]), hi = std::max(hi, back.xyz[i]);
        EXPECT_EQ(pos["min"][a].get<float>(), lo) << a;
        EXPECT_EQ(pos["max"][a].get<float>(), hi) << a;
    }
}

TEST(GltfWriter, PlainGlbRoundTripsExactlyWithNormals) {
    TempDir dir;
    Soup mesh = read_soup(fixture("drc/elephant_normals_sequential_cl0.drc"));  // 5558 triangles
    io::WriteOptions o;
    o.format_options.set(io::GltfSettings{Compression::kNone});
    o.normals = true;
    write_soup(mesh, dir / "p.glb", o);
    expect_valid(dir / "p.glb");
    json doc = glb_json(dir / "p.glb");
    EXPECT_FALSE(doc.contains("extensionsRequired"));
    EXPECT_TRUE(doc["meshes"][0]["primitives"][0]["attributes"].contains("NORMAL"));
    EXPECT_EQ(read_soup(dir / "p.glb").xyz, mesh.xyz);
}

TEST(GltfWriter, GltfWithBinSideFileBothWaysIsValid) {
    TempDir dir;
    Soup mesh = read_soup(fixture("drc/elephant_normals_sequential_cl0.drc"));  // 5558 triangles
    for (bool draco : {false, true}) {
        SCOPED_TRACE(draco);
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{draco ? Compression::kDraco : Compression::kNone});
        o.normals = draco;
        write_soup(mesh, dir / "scene one.gltf", o);
        ASSERT_TRUE(fs::exists(dir / "scene one.bin"));
        json doc = json::parse(slurp(dir / "scene one.gltf"));
        EXPECT_EQ(doc["buffers"][0]["uri"], "scene%20one.bin");
        expect_valid(dir / "scene one.gltf");
        Soup back = read_soup(dir / "scene one.gltf");
        if (draco)
            expect_within_quantization_bound(mesh, back, 14);
        else
            EXPECT_EQ(back.xyz, mesh.xyz);
    }
}

TEST(GltfWriter, RefusesToReplaceAnotherFilesBuffer) {
    TempDir dir;
    Soup cube = read_soup(fixture("cube.bin.stl"));
    io::WriteOptions o;
    o.format_options.set(io::GltfSettings{Compression::kNone});
    // scene.bin exists, scene.gltf does not: the .bin is someone else's and stays as it was.
    std::ofstream(dir / "scene.bin") << "not mine";
    try {
        write_soup(cube, dir / "scene.gltf", o);
        ADD_FAILURE() << "no error";
    } catch (const io::Error& e) {
        EXPECT_NE(std::string(e.what()).find("scene.bin, which exists but belongs to no earlier"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(slurp(dir / "scene.bin"), "not mine");
    EXPECT_FALSE(fs::exists(dir / "scene.gltf"));
    // scene.gltf exists too but does not use scene.bin (it has no buffers): still someone
    // else's, for example the buffer of the very glTF being converted.
    std::ofstream(dir / "scene.gltf") << R"({"asset":{"version":"2.0"},"scenes":[{}],"scene":0})";
    try {
        write_soup(cube, dir / "scene.gltf", o);
        ADD_FAILURE() << "no error";
    } catch (const io::Error& e) {
        EXPECT_NE(std::string(e.what()).find("scene.bin, which the existing"), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(dir / "scene.bin"), "not mine");
    // A pair written earlier is replaced as a pair.
    fs::remove(dir / "scene.bin");
    fs::remove(dir / "scene.gltf");
    write_soup(cube, dir / "scene.gltf", o);
    write_soup(cube, dir / "scene.gltf", o);
    EXPECT_EQ(read_soup(dir / "scene.gltf").xyz, cube.xyz);
}

TEST(GltfWriter, SmallestIndexTypeAndEmptyMeshAreValid) {
    TempDir dir;
    Soup cube = read_soup(fixture("cube.bin.stl"));
    io::WriteOptions o;
    o.format_options.set(io::GltfSettings{Compression::kNone});
    write_soup(cube, dir / "cube.glb", o);
    expect_valid(dir / "cube.glb");
    json doc = glb_json(dir / "cube.glb");
    const json& prim = doc["meshes"][0]["primitives"][0];
    EXPECT_EQ(doc["accessors"][prim["indices"].get<int>()]["componentType"], 5121);  // 8 vertices: unsigned byte
    EXPECT_EQ(doc["accessors"][prim["attributes"]["POSITION"].get<int>()]["count"], 8);

    write_soup(Soup{}, dir / "empty.glb");
    expect_valid(dir / "empty.glb");
    EXPECT_EQ(read_soup(dir / "empty.glb").triangles(), 0u);
}

TEST(GltfWriter, UnfinishedGltfLeavesNeitherFile) {
    TempDir dir;
    Soup cube = read_soup(fixture("cube.bin.stl"));
    {
        io::Output out = io::open_output(dir / "c.gltf", {}, {});
        io::TriangleChunk chunk(16);
        for (size_t t = 0; t < cube.triangles(); ++t) {
            float tri[9];
            std::copy(&cube.xyz[9 * t], &cube.xyz[9 * t] + 9, tri);
            chunk.push(tri);
        }
        out.write(chunk);
    }  // destroyed without finish()
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

// Both files of a .gltf pair are written out before either is renamed: the .bin used to be
// renamed into place first, so a disk with room for it alone kept a .bin that belonged to no
// .gltf, and the next try was refused because of it.
TEST(GltfWriter, AFullDiskLeavesNeitherFileOfThePair) {
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    write_soup(bunny, dir / "probe.gltf");
    const uint64_t bin_pages = (fs::file_size(dir / "probe.bin") + 4095) / 4096;
    fs::create_directory(dir / "small");
    if (std::system(("mount -t tmpfs -o size=1M tmpfs '" + dir / "small" + "' 2>/dev/null").c_str()) != 0)
        GTEST_SKIP() << "cannot mount a small tmpfs here";
    struct statvfs vfs;
    ASSERT_EQ(::statvfs((dir / "small").c_str(), &vfs), 0);
    const uint64_t room = uint64_t{vfs.f_bavail} * vfs.f_frsize;
    ASSERT_GT(room, bin_pages * 4096);
    std::ofstream(dir / "small/filler", std::ios::binary) << std::string(room - bin_pages * 4096, '\0');
    std::string error;
    try {
        write_soup(bunny, dir / "small/b.gltf");
    } catch (const io::Error& e) {
        error = e.what();
    }
    std::vector<std::string> left;
    for (const auto& entry : fs::directory_iterator(dir / "small")) left.push_back(entry.path().filename());
    std::system(("umount '" + dir / "small" + "'").c_str());
    EXPECT_NE(error.find("No space left on device"), std::string::npos) << error;
    EXPECT_EQ(left, std::vector<std::string>{"filler"});
}

// A .gltf written into a FIFO (or a device, or stdout) has no directory entry that a .bin
// could sit beside: its buffer goes inside as a data URI. It used to create "ff.bin" beside
// the FIFO (and /dev/null.bin for /dev/null).
TEST(GltfWriter, AGltfIntoAFifoCarriesItsBuffer) {
    TempDir dir;
    ASSERT_EQ(::mkfifo((dir / "ff.gltf").c_str(), 0600), 0);
    std::string got;
    std::thread reader([&] { got = slurp(dir / "ff.gltf"); });
    io::WriteOptions o;
    o.format_options.set(io::GltfSettings{Compression::kNone});
    write_soup(read_soup(fixture("cube.bin.stl")), dir / "ff.gltf", o);
    reader.join();
    const json doc = json::parse(got);
    EXPECT_TRUE(doc["buffers"][0]["uri"].get<std::string>().starts_with("data:application/octet-stream;base64,"));
    EXPECT_FALSE(fs::exists(dir / "ff.bin"));
}

TEST(GltfWriter, RefusesPastMemoryBudget) {
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    for (bool draco : {false, true}) {
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{draco ? Compression::kDraco : Compression::kNone});
        o.memory_budget_bytes = 1 << 20;
        try {
            write_soup(bunny, dir / "b.glb", o);
            ADD_FAILURE() << "no memory error";
        } catch (const io::Error& e) {
            EXPECT_NE(std::string(e.what()).find("; give the memory budget "), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(GltfWriter, MeshoptGlbIsValidAndWithinQuantizationBound) {
    // --compress meshopt, as gltfpack -cc writes it: 14-bit positions (KHR_mesh_quantization)
    // dequantized by the node's transform, vertex and index streams compressed in buffer 0,
    // their views in a data-less fallback buffer.
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    io::WriteOptions o;
    o.format_options.set(io::GltfSettings{Compression::kMeshopt});
    write_soup(bunny, dir / "b.glb", o);
    expect_valid(dir / "b.glb");
    json doc = glb_json(dir / "b.glb");
    EXPECT_EQ(doc["extensionsRequired"], json::array({"EXT_meshopt_compression", "KHR_mesh_quantization"}));
    ASSERT_EQ(doc["buffers"].size(), 2u);
    EXPECT_FALSE(doc["buffers"][1].contains("uri"));
    EXPECT_EQ(doc["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"], true);
    std::set<std::string> modes;
    for (const json& view : doc["bufferViews"]) {
        EXPECT_EQ(view["buffer"], 1) << view.dump();
        const json& ext = view["extensions"]["EXT_meshopt_compression"];
        EXPECT_EQ(ext["buffer"], 0);
        modes.insert(ext["mode"].get<std::string>());
    }
    EXPECT_EQ(modes, (std::set<std::string>{"ATTRIBUTES", "TRIANGLES"}));
    const json& prim = doc["meshes"][0]["primitives"][0];
    const json& pos = doc["accessors"][prim["attributes"]["POSITION"].get<int>()];
    EXPECT_EQ(pos["componentType"], 5123);
    EXPECT_EQ(pos["max"], json::array({16383, 16239, 12698}));  // gltfpack's, on the same bunny
    EXPECT_EQ(doc["accessors"][prim["indices"].get<int>()]["count"], 3 * 69451);
    const Quantization q(bunny, 14);
    EXPECT_FLOAT_EQ(doc["nodes"][0]["scale"][0].get<float>(), q.range / 16383);
    io::MeshHeader h;
    Soup back = read_soup(dir / "b.glb", io::TriangleChunk::kDefaultCapacity, &h);
    EXPECT_EQ(h.triangle_count, 69451u);
    expect_within_quantization_bound(bunny, back, 14);
    EXPECT_NE(back.xyz.size() > 9 ? std::vector<float>(back.xyz.begin(), back.xyz.begin() + 9) : back.xyz,
              std::vector<float>(bunny.xyz.begin(), bunny.xyz.begin() + 9))
        << "the triangles are reordered for the vertex cache";
}

TEST(GltfWriter, MeshoptGltfWithNormalsAndItsBinIsValid) {
    // A .gltf keeps buffer 0 in its .bin; the fallback buffer has no file. --normals adds
    // 8-bit octahedral normals (meshopt's OCTAHEDRAL filter), as gltfpack -cc does.
    TempDir dir;
    Soup mesh = read_soup(fixture("drc/elephant_normals_sequential_cl0.drc"));
    io::WriteOptions o;
    o.format_options.set(io::GltfSettings{Compression::kMeshopt});
    o.normals = true;
    write_soup(mesh, dir / "e.gltf", o);
    expect_valid(dir / "e.gltf");
    json doc = json::parse(slurp(dir / "e.gltf"));
    EXPECT_EQ(doc["buffers"][0]["uri"], "e.bin");
    EXPECT_EQ(doc["buffers"][0]["byteLength"], fs::file_size(dir / "e.bin"));
    EXPECT_FALSE(doc["buffers"][1].contains("uri"));
    const json& prim = doc["meshes"][0]["primitives"][0];
    const json& normal = doc["accessors"][prim["attributes"]["NORMAL"].get<int>()];
    EXPECT_EQ(normal["componentType"], 5120);
    EXPECT_EQ(normal["normalized"], true);
    EXPECT_EQ(doc["bufferViews"][normal["bufferView"].get<int>()]["extensions"]["EXT_meshopt_compression"]["filter"],
              "OCTAHEDRAL");
    Soup back = read_soup(dir / "e.gltf");
    expect_within_quantization_bound(mesh, back, 14);
}

TEST(GltfWriter, MeshoptKeepsTheTriangleOrderOfASortedStream) {
    // A stream that says it is sorted (meshstream sort's output) keeps its order: only the
    // vertices are renumbered for the codec (whose index coder may rotate a triangle's corners,
    // keeping its winding). Others are reordered for the vertex cache.
    TempDir dir;
    Soup mesh = read_soup(fixture("drc/elephant_normals_sequential_cl0.drc"));
    io::WriteOptions o;
    o.format_options.set(io::GltfSettings{Compression::kMeshopt});
    o.sorted_axis = 1;
    const Quantization q(mesh, 14);
    auto in_order = [&](const Soup& back) {
        size_t same = 0;
        for (size_t t = 0; t < mesh.triangles() && t < back.triangles(); ++t) {
            TriKey a, b;
            for (int i = 0; i < 9; ++i)
                a[i] = q.quantize(mesh.xyz[9 * t + i], i % 3), b[i] = q.snap(back.xyz[9 * t + i], i % 3);
            same += canonical(a) == canonical(b);
        }
        return same;
    };
    write_soup(mesh, dir / "sorted.glb", o);
    Soup back = read_soup(dir / "sorted.glb");
    ASSERT_EQ(back.triangles(), mesh.triangles());
    EXPECT_EQ(in_order(back), mesh.triangles());
    expect_within_quantization_bound(mesh, back, 14);
    o.sorted_axis.reset();
    write_soup(mesh, dir / "free.glb", o);
    EXPECT_LT(in_order(read_soup(dir / "free.glb")), mesh.triangles() / 10);
}

// Issue 21 §1: the writers receive degenerate triangles now that convert and sort are lossless.
// glTF holds them (plain and meshopt: every triangle comes out); Draco's encoder drops those
// with a repeated vertex and says how many; NaN no accessor holds. --strict refuses both.
TEST(GltfWriter, MeshesOnOneGridDecodeASharedPositionToOneFloat) {
    // The bunny's two halves written apart on one grid (the tiles of a tileset): each position
    // both halves hold decodes to the same float in both, with meshopt and with Draco; each on
    // its own box, many do not. A position beyond the grid is decoded on its side.
    TempDir dir;
    const Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    Soup halves[2];
    const size_t cut = 9 * (bunny.triangles() / 2);
    halves[0].xyz.assign(bunny.xyz.begin(), bunny.xyz.begin() + cut);
    halves[1].xyz.assign(bunny.xyz.begin() + cut, bunny.xyz.end());
    io::GltfSettings::Grid grid;
    for (int a = 0; a < 3; ++a) grid.origin[a] = -0.1f;
    grid.extent = 0.3f;
    // Positions in both halves, as written.
    std::set<std::array<float, 3>> first, shared;
    for (size_t i = 0; i < halves[0].xyz.size(); i += 3) first.insert({halves[0].xyz[i], halves[0].xyz[i + 1], halves[0].xyz[i + 2]});
    for (size_t i = 0; i < halves[1].xyz.size(); i += 3)
        if (first.count({halves[1].xyz[i], halves[1].xyz[i + 1], halves[1].xyz[i + 2]}))
            shared.insert({halves[1].xyz[i], halves[1].xyz[i + 1], halves[1].xyz[i + 2]});
    ASSERT_GT(shared.size(), 100u);
    // What each shared position decodes to in a half: the decoded positions within two steps
    // of it (steps of 5 µm, vertices of the bunny farther apart).
    auto decoded = [&](const std::string& path, const Soup& written) {
        const Soup back = read_soup(path);
        EXPECT_EQ(back.triangles(), written.triangles()) << path;
        const float tol = 2e-5f;
        std::map<std::array<float, 3>, std::array<float, 3>> out;
        for (size_t i = 0; i < back.xyz.size(); i += 3) {
            const std::array<float, 3> p = {back.xyz[i], back.xyz[i + 1], back.xyz[i + 2]};
            for (auto it = shared.lower_bound({p[0] - tol, -1e9f, -1e9f}); it != shared.end() && (*it)[0] <= p[0] + tol;
                 ++it)
                if (std::fabs((*it)[1] - p[1]) <= tol && std::fabs((*it)[2] - p[2]) <= tol) out[*it] = p;
        }
        return out;
    };
    for (const Compression c : {Compression::kMeshopt, Compression::kDraco}) {
        io::GltfSettings gs(c);
        gs.grid = grid;
        io::WriteOptions o;
        o.format_options.set(gs);
        write_soup(halves[0], dir / "a.glb", o);
        write_soup(halves[1], dir / "b.glb", o);
        expect_valid(dir / "a.glb");
        const auto a = decoded(dir / "a.glb", halves[0]), b = decoded(dir / "b.glb", halves[1]);
        size_t same = 0, compared = 0;
        for (const auto& [input, p] : a)
            if (auto it = b.find(input); it != b.end()) ++compared, same += it->second == p;
        EXPECT_GT(compared, shared.size() / 2) << int(c);
        EXPECT_EQ(same, compared) << int(c);
        // Each on its own box: the same positions decode apart.
        io::WriteOptions own;
        own.format_options.set(io::GltfSettings(c));
        write_soup(halves[0], dir / "a.glb", own);
        write_soup(halves[1], dir / "b.glb", own);
        const auto a2 = decoded(dir / "a.glb", halves[0]), b2 = decoded(dir / "b.glb", halves[1]);
        size_t apart = 0;
        for (const auto& [input, p] : a2)
            if (auto it = b2.find(input); it != b2.end()) apart += it->second != p;
        EXPECT_GT(apart, compared / 4) << int(c);

        // Beyond the grid: decoded on its side.
        Soup out;
        out.xyz = {0.f, 0.f, 0.f, 0.1f, 0.f, 0.f, 0.f, 0.5f, 0.f};
        write_soup(out, dir / "out.glb", o);
        const Soup back = read_soup(dir / "out.glb");
        ASSERT_EQ(back.triangles(), 1u) << int(c);
        float most = 0;
        for (float v : back.xyz) most = std::max(most, v);
        EXPECT_NEAR(most, 0.2f, 1e-4f) << int(c);

        // A triangle thinner than the grid's step is said to be flattened by the grid.
        if (c == Compression::kDraco) {
            Soup thin;
            thin.xyz = {0.f, 0.f, 0.f, 0.1f, 0.f, 0.f, 0.05f, 1e-7f, 0.f};
            const std::vector<std::string> notes = write_soup(thin, dir / "thin.glb", o);
            ASSERT_EQ(notes.size(), 1u);
            EXPECT_NE(notes[0].find("1 of the 1 triangles have zero area once decoded: thinner than the step of the "
                                    "16-bit quantization grid they were written on"),
                      std::string::npos)
                << notes[0];
        }

        // Bits a codec cannot hold are refused, naming the file.
        io::GltfSettings bad = gs;
        bad.grid->bits = c == Compression::kMeshopt ? 17 : 31;
        io::WriteOptions bo;
        bo.format_options.set(bad);
        try {
            write_soup(halves[0], dir / "bad.glb", bo);
            ADD_FAILURE() << "no error for " << bad.grid->bits << " bits";
        } catch (const io::Error& e) {
            EXPECT_NE(std::string(e.what()).find("bad.glb: the positions' quantization grid needs 1-"),
                      std::string::npos)
                << e.what();
        }
        EXPECT_FALSE(fs::exists(dir / "bad.glb"));
    }
}

Soup degenerate_soup() {
    Soup s;
    s.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0,   // fine
             0, 0, 0, 1, 0, 0, 0, 0, 0,   // two corners at one position
             0, 0, 0, 1, 0, 0, 2, 0, 0,   // three distinct collinear corners: zero area
             5, 5, 5, 5, 5, 5, 5, 5, 5,   // a point
             0, 0, 1, 1, 0, 1, 0, 1, 1};  // fine
    return s;
}

TEST(GltfWriter, KeepsDegenerateAndZeroAreaTrianglesExceptWithDraco) {
    TempDir dir;
    const Soup soup = degenerate_soup();
    for (auto c : {Compression::kNone, Compression::kMeshopt}) {
        SCOPED_TRACE(int(c));
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{c});
        EXPECT_TRUE(write_soup(soup, dir / "d.glb", o).empty());
        const json report = validate(dir / "d.glb");
        EXPECT_EQ(report["issues"]["numErrors"], 0) << report.dump(2);
        EXPECT_EQ(report["issues"]["numWarnings"], 0) << report.dump(2);
        Soup back = read_soup(dir / "d.glb");
        ASSERT_EQ(back.triangles(), 5u);
        if (c == Compression::kNone)
            EXPECT_EQ(back.xyz, soup.xyz);
        else
            EXPECT_EQ(triangle_multiset(back).size(), 5u);
    }
    // Draco: the two with a repeated vertex are left out and counted; --strict names the first.
    const std::vector<std::string> notes = write_soup(soup, dir / "d.glb");
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], dir / "d.glb" +
                            ": 2 of the 5 triangles have two corners at one vertex (degenerate), which "
                            "Draco's encoder drops: left out (write without Draco to keep them; strict mode "
                            "makes this an error)");
    EXPECT_EQ(read_soup(dir / "d.glb").triangles(), 3u);
    io::WriteOptions strict;
    strict.strict = true;
    try {
        write_soup(soup, dir / "s.glb", strict);
        ADD_FAILURE() << "accepted";
    } catch (const io::Error& e) {
        EXPECT_EQ(std::string(e.what()), dir / "s.glb" +
                                             ": triangle 1 has two corners at one vertex, which Draco's "
                                             "encoder drops (strict mode)");
    }
    strict.format_options.set(io::GltfSettings{Compression::kMeshopt});
    EXPECT_TRUE(write_soup(soup, dir / "s.glb", strict).empty()) << "glTF holds them: nothing to refuse";
}

TEST(GltfWriter, LeavesOutNonFiniteTrianglesOrRefusesThemUnderStrict) {
    TempDir dir;
    Soup soup = degenerate_soup();
    soup.xyz[9 * 2 + 4] = NAN;
    soup.xyz[9 * 4] = -INFINITY;
    for (auto c : {Compression::kNone, Compression::kMeshopt}) {
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{c});
        const std::vector<std::string> notes = write_soup(soup, dir / "n.glb", o);
        ASSERT_EQ(notes.size(), 1u);
        EXPECT_EQ(notes[0], dir / "n.glb" +
                                ": 2 of the 5 triangles have a NaN or infinite coordinate, which glTF "
                                "cannot store: left out (strict mode makes this an error)");
        expect_valid_allowing(dir / "n.glb", {"ACCESSOR_INDEX_TRIANGLE_DEGENERATE"});
        EXPECT_EQ(read_soup(dir / "n.glb").triangles(), 3u);
        o.strict = true;
        try {
            write_soup(soup, dir / "s.glb", o);
            ADD_FAILURE() << "accepted";
        } catch (const io::Error& e) {
            EXPECT_NE(std::string(e.what()).find("triangle 2 has a NaN or infinite coordinate, which glTF cannot store "
                                                 "(strict mode)"),
                      std::string::npos)
                << e.what();
        }
        EXPECT_FALSE(fs::exists(dir / "s.glb"));
    }
}

// Channels: NORMAL, COLOR_0, TEXCOORD_0 and materials with their texture, read from every
// encoding of the same box and written back with every compression.

std::string box_png() { return slurp(fixture("gltf/BoxTextured_external/CesiumLogoFlat.png")); }

std::string texture_bytes(const Mesh& m, size_t material = 0) {
    if (material >= m.header.materials.size() || !m.header.materials[material].texture) return {};
    const auto& b = m.header.materials[material].texture->bytes;
    return {reinterpret_cast<const char*>(b.data()), b.size()};
}

// The Cesium logo is 211 × 211 pixels: the validator notes that, as it does for the sample file.
const std::set<std::string> kNpot = {"IMAGE_NPOT_DIMENSIONS"};

TEST(GltfChannels, BoxTexturedReadsNormalsUvsAndItsTextureFromEveryEncoding) {
    const Mesh ref = read_mesh(fixture("gltf/BoxTextured.glb"));
    const io::Channels& ch = ref.header.channels;
    ASSERT_EQ(ref.triangles(), 12u);
    EXPECT_TRUE(ch.normal);
    EXPECT_EQ(ch.uv_sets, 1);
    EXPECT_TRUE(ch.material);
    EXPECT_FALSE(ch.color);
    EXPECT_TRUE(ch.vertex_id);
    ASSERT_EQ(ref.header.materials.size(), 1u);
    EXPECT_EQ(ref.header.materials[0].name, "Texture");
    EXPECT_EQ(ref.header.materials[0].texture->mime_type, "image/png");
    EXPECT_EQ(texture_bytes(ref), box_png());
    // 24 vertices: each face its own four, for its normal and texture coordinates.
    EXPECT_EQ(std::set<uint64_t>(ref.ids.begin(), ref.ids.end()).size(), 24u);
    // The node turns the box -90° about x: each normal (turned with it) is its face's.
    for (size_t t = 0; t < 12; ++t) {
        const float* p = &ref.xyz[9 * t];
        double e1[3], e2[3], n[3];
        for (int a = 0; a < 3; ++a) e1[a] = p[3 + a] - p[a], e2[a] = p[6 + a] - p[a];
        n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2],
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) EXPECT_NEAR(ref.normals[9 * t + 3 * k + a], n[a] / len, 1e-6) << t;
    }
    // Texture coordinates as the chunk holds them (v up): the file's (0.0, 1.0) corner of the
    // first face is its top left, (6, 0) in glTF's v-down convention.
    float umax = 0, vmin = 1;
    for (size_t i = 0; i < ref.uvs.size(); i += 2)
        umax = std::max(umax, ref.uvs[i]), vmin = std::min(vmin, ref.uvs[i + 1]);
    EXPECT_FLOAT_EQ(umax, 6.0f);
    EXPECT_NEAR(vmin, 0.0f, 1e-6);

    struct Case {
        const char* file;
        double position, normal, uv;  // the encoding's quantization
    } cases[] = {
        {"gltf/BoxTextured_embedded.gltf", 0, 0, 0},
        {"gltf/BoxTextured_external/BoxTextured.gltf", 0, 0, 0},
        // draco_transcoder's defaults: positions 11 bits, normals 8, texture coordinates 10
        // over their range (6): steps 1/2047, about 2/255 and 6/1023.
        {"gltf/BoxTextured_draco_transcoder.glb", 0.5 / 2047, 4.0 / 255, 0.5 * 6 / 1023},
        // gltfpack -cc: positions 14 bits, normals 8-bit, texture coordinates 12 bits, undone
        // by the node's scale and KHR_texture_transform.
        {"gltf/BoxTextured_gltfpack_cc.glb", 0.5 / 16383, 2.0 / 127, 0.5 * 6 / 4095},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        const Mesh m = read_mesh(fixture(c.file));
        EXPECT_EQ(m.header.channels, ch);
        const ChannelErrors e = compare_meshes(ref, m, c.position * 1.0001 + 1e-7);
        EXPECT_EQ(e.unmatched, 0u);
        EXPECT_EQ(e.material_mismatches, 0u);
        EXPECT_LE(e.normal, c.normal * 1.0001 + 1e-7);
        EXPECT_LE(e.uv, c.uv * 1.0001 + 1e-6);
        // draco_transcoder's image view is padded to 4 bytes with zeros, which the file counts.
        const std::string bytes = texture_bytes(m), png = box_png();
        EXPECT_EQ(bytes.substr(0, png.size()), png);
        EXPECT_EQ(bytes.find_first_not_of('\0', png.size()), std::string::npos);
        EXPECT_LT(bytes.size(), png.size() + 4);
    }
    // The external image is one of the document's side files.
    io::MeshHeader h;
    read_soup(fixture("gltf/BoxTextured_external/BoxTextured.gltf"), 100, &h);
    EXPECT_EQ(h.side_files.size(), 2u);
    EXPECT_TRUE(std::any_of(h.side_files.begin(), h.side_files.end(),
                            [](const std::string& f) { return f.ends_with("CesiumLogoFlat.png"); }));
}

TEST(GltfChannels, BoxTexturedRoundTripsThroughEveryCompression) {
    TempDir dir;
    const Mesh ref = read_mesh(fixture("gltf/BoxTextured.glb"));
    struct Case {
        Compression compression;
        const char* name;
        double position, normal;  // meshopt: 14-bit positions, 8-bit octahedral normals; Draco: 14 and 10 bits
    } cases[] = {
        {Compression::kNone, "none.glb", 0, 0},
        {Compression::kNone, "none.gltf", 0, 0},
        {Compression::kMeshopt, "meshopt.glb", 0.5 / 16383, 2.0 / 127},
        {Compression::kMeshopt, "meshopt.gltf", 0.5 / 16383, 2.0 / 127},
        {Compression::kDraco, "draco.glb", 0.5 / 16383, 4.0 / 1023},
        {Compression::kDraco, "draco.gltf", 0.5 / 16383, 4.0 / 1023},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{c.compression});
        EXPECT_TRUE(write_mesh(ref, dir / c.name, o).empty());
        expect_valid_allowing(dir / c.name, kNpot);
        const Mesh back = read_mesh(dir / c.name);
        EXPECT_EQ(back.header.channels, ref.header.channels);
        const ChannelErrors e = compare_meshes(ref, back, c.position * 1.0001 + 1e-7);
        EXPECT_EQ(e.unmatched, 0u);
        EXPECT_EQ(e.material_mismatches, 0u);
        EXPECT_LE(e.normal, c.normal * 1.0001 + 1e-7);
        // Texture coordinates: float with meshopt and none, 12 bits over their range with Draco.
        EXPECT_LE(e.uv, c.compression == Compression::kDraco ? 0.5 * 6 / 4095 * 1.0001 + 1e-6 : 0.0);
        EXPECT_EQ(texture_bytes(back), box_png());
        EXPECT_EQ(std::set<uint64_t>(back.ids.begin(), back.ids.end()).size(), 24u) << "seams kept";
    }
    // A .gltf's texture is a file beside it, named in its images.
    const json doc = json::parse(slurp(dir / "none.gltf"));
    ASSERT_EQ(doc["images"].size(), 1u);
    EXPECT_EQ(doc["images"][0]["uri"], "none_0.png");
    EXPECT_EQ(slurp(dir / "none_0.png"), box_png());
}

TEST(GltfChannels, ColoursKeepTheirTypeAndValues) {
    TempDir dir;
    // CGAL's cactus: RGB as uchar (PLY and Draco), and one float RGBA triangle.
    for (const char* file :
         {"ply/cactus_vcolor.binary_le.ply", "drc/cactus_vcolor_edgebreaker.drc", "ply/float-color.ply"}) {
        SCOPED_TRACE(file);
        const Mesh ref = read_mesh(fixture(file));
        ASSERT_TRUE(ref.header.channels.color);
        const io::ColorFormat format = *ref.header.channels.color;
        const bool is_float = format.type == io::ScalarType::kFloat32;
        for (auto [c, name] : {std::pair{Compression::kNone, "c.glb"}, std::pair{Compression::kMeshopt, "c.gltf"},
                               std::pair{Compression::kDraco, "d.glb"}}) {
            SCOPED_TRACE(name);
            io::WriteOptions o;
            o.format_options.set(io::GltfSettings{c});
            write_mesh(ref, dir / name, o);
            expect_valid(dir / name);
            const Mesh back = read_mesh(dir / name);
            ASSERT_TRUE(back.header.channels.color);
            EXPECT_EQ(*back.header.channels.color, format);
            const bool draco = c == Compression::kDraco;
            // Positions: 14 bits over the largest extent.
            float lo = ref.xyz[0], hi = ref.xyz[0];
            for (float x : ref.xyz) lo = std::min(lo, x), hi = std::max(hi, x);
            const double step = c == Compression::kNone ? 0 : (hi - lo) / 16383.0;
            const ChannelErrors e = compare_meshes(ref, back, step);
            EXPECT_EQ(e.unmatched, 0u);
            // Integer colours are stored as they are; float ones quantized by Draco (--draco-qc
            // 10 bits over their range, at most 1).
            EXPECT_LE(e.color, draco && is_float ? 0.5 / 1023 * 1.0001 : 0.0);
        }
    }
    // 16-bit RGBA, made here: glTF's normalized unsigned short, VEC4.
    Mesh m;
    m.header.channels.color = io::ColorFormat{io::ScalarType::kUInt16, true};
    std::mt19937 rng(7);
    for (int t = 0; t < 50; ++t)
        for (int k = 0; k < 9; ++k) m.xyz.push_back(float(rng() % 1000) / 10);
    for (int i = 0; i < 50 * 12; ++i) m.colors.push_back(float(rng() % 65536) / 65535.0f);
    write_mesh(m, dir / "u16.glb", [] {
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{Compression::kNone});
        return o;
    }());
    expect_valid(dir / "u16.glb");
    const json doc = glb_json(dir / "u16.glb");
    const json& acc = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"].get<int>()];
    EXPECT_EQ(acc["componentType"], 5123);
    EXPECT_EQ(acc["type"], "VEC4");
    EXPECT_EQ(acc["normalized"], true);
    const Mesh back = read_mesh(dir / "u16.glb");
    EXPECT_EQ(*back.header.channels.color, (io::ColorFormat{io::ScalarType::kUInt16, true}));
    const ChannelErrors e = compare_meshes(m, back, 0);
    EXPECT_EQ(e.unmatched, 0u);
    EXPECT_LE(e.color, 0.5 / 65535);  // the same 16-bit value
}

TEST(GltfChannels, DracoElephantsNormalsThroughEveryCompression) {
    TempDir dir;
    const Mesh ref = read_mesh(fixture("drc/elephant_normals_sequential_cl0.drc"));
    ASSERT_TRUE(ref.header.channels.normal);
    for (auto [c, name, normal] :
         {std::tuple{Compression::kNone, "n.glb", 0.0}, std::tuple{Compression::kMeshopt, "m.glb", 2.0 / 127},
          std::tuple{Compression::kDraco, "d.glb", 4.0 / 1023}}) {
        SCOPED_TRACE(name);
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{c});
        write_mesh(ref, dir / name, o);
        expect_valid(dir / name);
        const Mesh back = read_mesh(dir / name);
        const ChannelErrors e = compare_meshes(ref, back, c == Compression::kNone ? 0 : 2e-4);
        EXPECT_EQ(e.unmatched, 0u);
        EXPECT_LE(e.normal, normal);
    }
}

TEST(GltfChannels, PlyNormalsAndTextureCoordinatesThroughGlbAndDrc) {
    // cube_uv.ply: 24 corner vertices with normals and s/t; the elephant: per-vertex normals.
    TempDir dir;
    for (const char* file : {"ply/cube_uv.ply", "ply/elephant_normals.binary_be.ply"}) {
        SCOPED_TRACE(file);
        const Mesh ref = read_mesh(fixture(file));
        ASSERT_TRUE(ref.header.channels.normal);
        const bool uv = ref.header.channels.uv_sets > 0;
        float lo = ref.xyz[0], hi = ref.xyz[0];
        for (float x : ref.xyz) lo = std::min(lo, x), hi = std::max(hi, x);
        const double step = 0.5 * (hi - lo) / 16383 * 1.0001 + 1e-7;
        float ulo = 0, uhi = 0;
        for (float x : ref.uvs) ulo = std::min(ulo, x), uhi = std::max(uhi, x);
        struct Case {
            const char* name;
            Compression compression;
            double position, normal, uv;
        } cases[] = {
            {"p.glb", Compression::kNone, 0, 0, 0},
            {"m.glb", Compression::kMeshopt, step, 2.0 / 127, 0},
            {"d.glb", Compression::kDraco, step, 4.0 / 1023, 0.5 * (uhi - ulo) / 4095 * 1.0001 + 1e-6},
            {"d.drc", Compression::kDraco, step, 4.0 / 1023, 0.5 * (uhi - ulo) / 4095 * 1.0001 + 1e-6},
        };
        for (const Case& c : cases) {
            SCOPED_TRACE(c.name);
            io::WriteOptions o;
            o.format_options.set(io::GltfSettings{c.compression});
            EXPECT_TRUE(write_mesh(ref, dir / c.name, o).empty());
            if (std::string(c.name).ends_with(".glb")) expect_valid(dir / c.name);
            const Mesh back = read_mesh(dir / c.name);
            EXPECT_TRUE(back.header.channels.normal);
            EXPECT_EQ(back.header.channels.uv_sets, ref.header.channels.uv_sets);
            const ChannelErrors e = compare_meshes(ref, back, c.position);
            EXPECT_EQ(e.unmatched, 0u);
            EXPECT_LE(e.normal, c.normal);
            if (uv) {
                EXPECT_LE(e.uv, c.uv);
            }
            // The vertices are the PLY's: 24 for the cube (its seams), the elephant's 2775.
            EXPECT_EQ(back.header.vertex_count.value_or(std::set<uint64_t>(back.ids.begin(), back.ids.end()).size()),
                      ref.header.vertex_count);
        }
    }
}

TEST(GltfRender, WrittenFilesRenderInThreeJs) {
    // What a web page shows: three.js's GLTFLoader (with MeshoptDecoder and DRACOLoader) in
    // headless Chromium loads each output, and the picture holds the mesh.
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    std::vector<std::string> files;
    for (auto [c, name] :
         {std::pair{Compression::kMeshopt, "meshopt.glb"}, std::pair{Compression::kDraco, "draco.glb"},
          std::pair{Compression::kNone, "plain.glb"}, std::pair{Compression::kMeshopt, "meshopt.gltf"}}) {
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{c});
        o.normals = true;
        write_soup(bunny, dir / name, o);
        files.push_back(dir / name);
    }
    // The textured box, as the sample file holds it, round-tripped with every compression, and
    // with positions only (the grey box a reader without texture coordinates and materials
    // gave).
    const size_t boxes = files.size();
    files.push_back(fixture("gltf/BoxTextured.glb"));
    const Mesh box = read_mesh(fixture("gltf/BoxTextured.glb"));
    for (auto [c, name] :
         {std::pair{Compression::kMeshopt, "box_meshopt.glb"}, std::pair{Compression::kDraco, "box_draco.glb"},
          std::pair{Compression::kNone, "box_plain.gltf"}}) {
        io::WriteOptions o;
        o.format_options.set(io::GltfSettings{c});
        write_mesh(box, dir / name, o);
        files.push_back(dir / name);
    }
    write_soup(read_soup(fixture("gltf/BoxTextured.glb")), dir / "box_grey.glb");
    files.push_back(dir / "box_grey.glb");

    const json report = render(dir, files);
    ASSERT_EQ(report.size(), files.size());
    for (size_t i = 0; i < boxes; ++i) {
        const json& r = report[i];
        SCOPED_TRACE(r.dump());
        EXPECT_EQ(r["triangles"], 69451);
        EXPECT_GT(r["covered"].get<double>(), 0.1);  // the bunny fills about 28 % of the frame
        EXPECT_GT(r["distinct"].get<int>(), 8);      // shaded, not a flat silhouette
    }
    // The same picture whatever the compression: quantization moves nothing visible.
    for (size_t i = 0; i < boxes; ++i)
        EXPECT_NEAR(report[i]["covered"].get<double>(), report[2]["covered"].get<double>(), 0.01) << report[i]["file"];
    // The boxes show the logo's colours as the sample does (its render: about 55 % of the
    // covered pixels saturated, mean RGB about (125, 149, 148)); the grey box shows none.
    const json& sample = report[boxes];
    EXPECT_GT(sample["saturated"].get<double>(), 0.3) << sample.dump();
    for (size_t i = boxes + 1; i < boxes + 4; ++i) {
        const json& r = report[i];
        SCOPED_TRACE(r.dump());
        EXPECT_EQ(r["triangles"], 12);
        EXPECT_NEAR(r["covered"].get<double>(), sample["covered"].get<double>(), 0.005);
        EXPECT_NEAR(r["saturated"].get<double>(), sample["saturated"].get<double>(), 0.05);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(r["mean"][c].get<double>(), sample["mean"][c].get<double>(), 4.0) << c;
    }
    const json& grey = report[boxes + 4];
    EXPECT_LT(grey["saturated"].get<double>(), 0.02) << grey.dump();
    EXPECT_GT(std::abs(grey["mean"][0].get<double>() - sample["mean"][0].get<double>()) +
                  std::abs(grey["mean"][2].get<double>() - sample["mean"][2].get<double>()),
              20.0)
        << grey.dump();
}

TEST(GltfFormat, DetectedByContentWhateverTheName) {
    TempDir dir;
    fs::copy_file(fixture("gltf/BoxTextured.glb"), dir / "a.bin");
    fs::copy_file(fixture("gltf/BoxTextured_embedded.gltf"), dir / "b.json");
    EXPECT_EQ(io::open_input(dir / "a.bin").format->name, "glb");
    EXPECT_EQ(io::open_input(dir / "b.json").format->name, "gltf");
}

}  // namespace
