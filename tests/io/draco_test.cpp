// Draco .drc tests: exact counts and settings on real files (bitstreams 1.1 and 2.2,
// edgebreaker and sequential), point-cloud refusal, truncation, chunk boundaries, lossy round
// trips within the quantization bound, Debian's draco_decoder agreeing on every file we write,
// vertex ids, normals, and the memory budget.
#include "io/draco.hpp"

#include "io/error.hpp"
#include "io/format.hpp"
#include "io/gltf.hpp"
#include "web_test_util.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <sstream>

using namespace web_test;

namespace {

std::string note(const io::MeshHeader& h, const std::string& key) {
    for (const auto& [k, v] : h.notes)
        if (k == key) return v;
    return "<missing>";
}

// Runs Debian's draco_decoder on `drc` and returns the (vertex, face) counts of its PLY output.
std::pair<uint64_t, uint64_t> draco_decoder_counts(const std::string& drc, const std::string& ply) {
    std::string tool = MESHSTREAM_DRACO_DECODER;
    EXPECT_TRUE(fs::exists(tool)) << "draco_decoder not found (" << tool << "); install Debian's 'draco' package";
    std::string out;
    EXPECT_EQ(run(quote(tool) + " -i " + quote(drc) + " -o " + quote(ply) + " 2>&1", &out), 0) << out;
    std::istringstream header(slurp(ply));
    std::string line;
    uint64_t vertices = 0, faces = 0;
    while (std::getline(header, line) && line != "end_header") {
        if (line.rfind("element vertex ", 0) == 0) vertices = std::stoull(line.substr(15));
        if (line.rfind("element face ", 0) == 0) faces = std::stoull(line.substr(13));
    }
    return {vertices, faces};
}

TEST(DracoReader, ExactCountsAndSettingsOnRealFiles) {
    struct Case {
        const char* file;
        uint64_t triangles;
        const char* draco;
        const char* attributes;
    } cases[] = {
        {"drc/bunny_v1.1_draco3d-npm.drc", 69451, "bitstream 1.1, edgebreaker connectivity", "position"},
        {"drc/cactus_vcolor_edgebreaker.drc", 1236, "bitstream 2.2, edgebreaker connectivity", "position, color"},
        {"drc/cube_quads.drc", 12, "bitstream 2.2, edgebreaker connectivity", "position"},
        {"drc/elephant_normals_sequential_cl0.drc", 5558, "bitstream 2.2, sequential connectivity", "position, normal"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        io::MeshHeader h;
        Soup s = read_soup(fixture(c.file), io::TriangleChunk::kDefaultCapacity, &h);
        EXPECT_EQ(s.triangles(), c.triangles);
        EXPECT_EQ(h.triangle_count, c.triangles);
        EXPECT_EQ(note(h, "draco"), c.draco);
        EXPECT_EQ(note(h, "attributes"), c.attributes);
        EXPECT_NE(note(h, "draco_qp"), "<missing>");
        for (float v : s.xyz) ASSERT_TRUE(std::isfinite(v));
    }
}

TEST(DracoReader, CountsAgreeWithDracoDecoder) {
    TempDir dir;
    for (const char* f : {"drc/bunny_v1.1_draco3d-npm.drc", "drc/elephant_normals_sequential_cl0.drc"}) {
        io::MeshHeader h;
        read_soup(fixture(f), 4096, &h);
        auto [v, t] = draco_decoder_counts(fixture(f), dir / "out.ply");
        EXPECT_EQ(h.vertex_count, v) << f;
        EXPECT_EQ(h.triangle_count, t) << f;
    }
}

TEST(DracoReader, RefusesPointCloudsByName) {
    try {
        read_soup(fixture("drc/points_pointcloud.drc"));
        FAIL() << "a point cloud was read as a mesh";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), fixture("drc/points_pointcloud.drc"));
        EXPECT_NE(std::string(e.what()).find("byte 7: geometry type is a Draco point cloud (no faces)"),
                  std::string::npos)
            << e.what();
    }
}

TEST(DracoReader, DetectedByMagicWhateverTheName) {
    TempDir dir;
    fs::copy_file(fixture("drc/cube_quads.drc"), dir / "cube.bin");
    io::Input in = io::open_input(dir / "cube.bin");
    EXPECT_EQ(in.format->name, "draco");
}

TEST(DracoReader, TruncationAtEveryByteThrows) {
    TempDir dir;
    std::string bytes = slurp(fixture("drc/cube_quads.drc"));
    ASSERT_EQ(bytes.size(), 80u);
    for (size_t n = 0; n < bytes.size(); ++n) {
        std::ofstream(dir / "t.drc", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(n));
        EXPECT_THROW(read_soup(dir / "t.drc"), io::Error) << "truncated to " << n << " bytes";
    }
}

TEST(DracoReader, ChunkBoundariesGiveIdenticalSoup) {
    Soup whole = read_soup(fixture("drc/elephant_normals_sequential_cl0.drc"));
    for (size_t cap : {size_t{1}, size_t{7}}) {
        Soup pieces = read_soup(fixture("drc/elephant_normals_sequential_cl0.drc"), cap);
        EXPECT_EQ(pieces.xyz, whole.xyz) << "capacity " << cap;
    }
}

TEST(DracoWriter, RoundTripStaysWithinQuantizationBound) {
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    ASSERT_EQ(bunny.triangles(), 69451u);
    for (int qp : {14, 11}) {
        SCOPED_TRACE(qp);
        io::WriteOptions o;
        o.format_options.set(io::DracoSettings{.position_bits = qp});
        write_soup(bunny, dir / "b.drc", o);
        io::MeshHeader h;
        Soup back = read_soup(dir / "b.drc", io::TriangleChunk::kDefaultCapacity, &h);
        EXPECT_EQ(note(h, "draco_qp"), std::to_string(qp) + " bits");
        EXPECT_EQ(note(h, "draco"), "bitstream 2.2, edgebreaker connectivity");
        double worst = expect_within_quantization_bound(bunny, back, qp);
        if (qp == 11) {
            EXPECT_GT(worst, 0.0) << "11 bits must move the 14-bit bunny's coordinates";
        }
        auto [v, t] = draco_decoder_counts(dir / "b.drc", dir / "b.ply");
        EXPECT_EQ(t, 69451u);
        EXPECT_EQ(h.vertex_count, v);
    }
}

TEST(DracoWriter, LevelZeroIsSequentialAndDecoderAgrees) {
    TempDir dir;
    Soup elephant = read_soup(fixture("drc/elephant_normals_sequential_cl0.drc"));
    io::WriteOptions o;
    o.format_options.set(io::DracoSettings{.level = 0});
    o.normals = true;
    write_soup(elephant, dir / "e.drc", o);
    io::MeshHeader h;
    Soup back = read_soup(dir / "e.drc", 1000, &h);
    EXPECT_EQ(note(h, "draco"), "bitstream 2.2, sequential connectivity");
    EXPECT_EQ(note(h, "attributes"), "position, normal");
    expect_within_quantization_bound(elephant, back, 14);
    auto [v, t] = draco_decoder_counts(dir / "e.drc", dir / "e.ply");
    EXPECT_EQ(t, 5558u);
    EXPECT_EQ(h.vertex_count, v);
}

TEST(DracoWriter, UsesVertexIdsInsteadOfWelding) {
    // Two triangles sharing an edge by position; with distinct vertex ids they stay 6 vertices.
    TempDir dir;
    const float quad[2][9] = {{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}};
    for (bool ids : {false, true}) {
        io::WriteOptions o;
        io::Output out = io::open_output(dir / "q.drc", {}, o);
        io::TriangleChunk chunk(4, ids ? io::Channels::ids_only() : io::Channels{});
        for (int t = 0; t < 2; ++t) {
            chunk.push(quad[t]);
            if (ids)
                for (int k = 0; k < 3; ++k) chunk.id_at(t)[k] = uint64_t(10 * t + k);
        }
        out.write(chunk);
        out.finish();
        io::MeshHeader h;
        Soup back = read_soup(dir / "q.drc", 16, &h);
        EXPECT_EQ(back.triangles(), 2u);
        EXPECT_EQ(h.vertex_count, ids ? 6u : 4u) << (ids ? "vertex ids" : "welding");
        auto [v, t] = draco_decoder_counts(dir / "q.drc", dir / "q.ply");
        EXPECT_EQ(v, ids ? 6u : 4u);
        EXPECT_EQ(t, 2u);
    }
}

TEST(DracoWriter, RefusesPastMemoryBudgetAndLeavesNoFile) {
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    io::WriteOptions o;
    o.memory_budget_bytes = 1 << 20;  // 1 MiB: the bunny needs several
    try {
        write_soup(bunny, dir / "b.drc", o);
        FAIL() << "no memory error";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), dir / "b.drc");
        EXPECT_NE(std::string(e.what()).find("over the memory budget of 1 MiB; give the memory budget "),
                  std::string::npos)
            << e.what();
    }
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

// A library caller reads the remedy in the library's words, never a command-line flag; the
// command names the flag (describe() with its names).
TEST(DracoReader, PastTheMemoryBudgetSaysSoInTheLibrarysWords) {
    TempDir dir;
    write_soup(read_soup(fixture("bunny_from_draco.bin.stl")), dir / "b.drc");
    io::ReadOptions o;
    o.memory_budget_bytes = 16 << 10;
    try {
        io::open_input(dir / "b.drc", {}, o);
        FAIL() << "read past the budget";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.message().rfind("Draco decodes whole files in memory and this one is over the memory budget of "
                                    "16 KiB; raise the memory budget",
                                    0),
                  0u)
            << e.message();
        EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
        const std::string flagged = e.describe(
            [](io::Setting s) { return std::string(s == io::Setting::kMemory ? "--memory" : io::setting_words(s)); });
        EXPECT_NE(flagged.find("16 KiB; raise --memory"), std::string::npos) << flagged;
    }
}

TEST(DracoWriter, RefusesEmptyMeshAndLeavesOutNonFiniteTriangles) {
    // No quantization holds a NaN: such a triangle is left out and counted in a note, or, with
    // --strict, refused by its number in the stream.
    TempDir dir;
    EXPECT_THROW(write_soup(Soup{}, dir / "empty.drc"), io::Error);
    Soup bad;
    bad.xyz = {0, 0, 0, 1, 0, 0, 0, NAN, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::vector<std::string> notes = write_soup(bad, dir / "nan.drc");
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], dir / "nan.drc" +
                            ": 1 of the 2 triangles have a NaN or infinite coordinate, which Draco cannot "
                            "store: left out (strict mode makes this an error)");
    EXPECT_EQ(read_soup(dir / "nan.drc").triangles(), 1u);
    io::WriteOptions strict;
    strict.strict = true;
    try {
        write_soup(bad, dir / "strict.drc", strict);
        FAIL();
    } catch (const io::Error& e) {
        EXPECT_NE(std::string(e.what()).find("triangle 0 has a NaN or infinite coordinate, which Draco cannot store "
                                             "(strict mode)"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "strict.drc"));
}

TEST(DracoWriter, RefusesExtentsItsQuantizerCannotStepThrough) {
    // Draco's quantization step is the largest extent / (2^bits − 1) in float. Wider than the
    // largest float, libdraco crashed (and left a temporary file); so small that the inverse
    // step overflows, every vertex decoded to one point far away. Both are refused, for .drc
    // and for Draco glTF alike, and nothing is left behind.
    TempDir dir;
    Soup huge;
    huge.xyz = {-2e38f, 0, 0, 2e38f, 0, 0, 0, 1, 0};
    Soup tiny;
    tiny.xyz = {0, 0, 0, 1e-35f, 0, 0, 0, 1e-35f, 0};
    for (const char* name : {"x.drc", "x.glb"}) {
        for (const auto& [soup, words] : {std::pair{&huge, "wider along an axis than a float can hold"},
                                          std::pair{&tiny, "too small for Draco's 14-bit quantization"}}) {
            try {
                write_soup(*soup, dir / name);
                ADD_FAILURE() << name << ": no error";
            } catch (const io::Error& e) {
                EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
            }
            EXPECT_TRUE(fs::is_empty(dir.path())) << name;
        }
    }
    // Fewer bits step through the tiny mesh exactly (its corners are the box's corners).
    io::WriteOptions o;
    o.format_options.set(io::DracoSettings{.position_bits = 8});
    write_soup(tiny, dir / "tiny.drc", o);
    EXPECT_EQ(read_soup(dir / "tiny.drc").xyz, tiny.xyz);
}

TEST(DracoWriter, SaysWhenQuantizationFlattensTriangles) {
    // A closed box 1000 × 0.02 × 0.02: at 14 bits the step (1000 / 16383 ≈ 0.06) is wider than
    // the box is thick, so every triangle decodes with zero area. Within the documented error
    // bound, but the file renders as nothing: the writer says so. At 20 bits it does not.
    TempDir dir;
    Soup box;
    const float x[2] = {0, 1000}, y[2] = {0, 0.02f}, z[2] = {0, 0.02f};
    auto corner = [&](int i) { return std::array<float, 3>{x[i & 1], y[(i >> 1) & 1], z[(i >> 2) & 1]}; };
    const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (const auto& f : faces)
        for (int k : f) {
            const auto c = corner(k);
            box.xyz.insert(box.xyz.end(), c.begin(), c.end());
        }
    for (const char* name : {"box.drc", "box.glb"}) {
        const std::vector<std::string> notes = write_soup(box, dir / name);
        ASSERT_EQ(notes.size(), 1u) << name;
        EXPECT_NE(
            notes[0].find(std::string(name) + ": 12 of the 12 triangles have zero area once decoded: thinner than "
                                              "Draco's 14-bit quantization step"),
            std::string::npos)
            << notes[0];
    }
    io::WriteOptions fine;
    fine.format_options.set(io::DracoSettings{.position_bits = 20});
    EXPECT_TRUE(write_soup(box, dir / "fine.drc", fine).empty());
    EXPECT_TRUE(write_soup(read_soup(fixture("bunny_from_draco.bin.stl")), dir / "bunny.drc").empty());
}

TEST(DracoWriter, RejectsOutOfRangeSettings) {
    // Each setting at the first value past either end of its range, for both writers that take
    // DracoSettings: refused when the output is opened with an io::OptionError naming the file,
    // the setting (in the library's words: no command-line flag) and the value, and nothing is
    // left behind. The ends themselves are accepted.
    TempDir dir;
    using io::Setting;
    struct Case {
        io::DracoSettings settings;
        Setting setting;
        const char* message;
    };
    const Case cases[] = {
        {{.position_bits = 0}, Setting::kDracoPositionBits, "the Draco position bits must be 1-30, got 0"},
        {{.position_bits = 31}, Setting::kDracoPositionBits, "the Draco position bits must be 1-30, got 31"},
        {{.normal_bits = 1}, Setting::kDracoNormalBits, "the Draco normal bits must be 2-30, got 1"},
        {{.normal_bits = 31}, Setting::kDracoNormalBits, "the Draco normal bits must be 2-30, got 31"},
        {{.texcoord_bits = 0}, Setting::kDracoTexcoordBits, "the Draco texture coordinate bits must be 1-30, got 0"},
        {{.texcoord_bits = 31}, Setting::kDracoTexcoordBits, "the Draco texture coordinate bits must be 1-30, got 31"},
        {{.color_bits = 0}, Setting::kDracoColorBits, "the Draco colour bits must be 1-30, got 0"},
        {{.color_bits = 31}, Setting::kDracoColorBits, "the Draco colour bits must be 1-30, got 31"},
        {{.level = -1}, Setting::kDracoLevel, "the Draco compression level must be 0-10, got -1"},
        {{.level = 11}, Setting::kDracoLevel, "the Draco compression level must be 0-10, got 11"},
    };
    for (const char* name : {"x.drc", "x.glb"})
        for (const Case& c : cases) {
            SCOPED_TRACE(std::string(name) + ": " + c.message);
            io::WriteOptions o;
            o.format_options.set(c.settings);
            try {
                io::open_output(dir / name, {}, o);
                ADD_FAILURE() << "accepted";
            } catch (const io::OptionError& e) {
                EXPECT_EQ(e.setting(), c.setting);
                EXPECT_EQ(std::string(e.what()), dir / name + ": " + c.message);
            }
            EXPECT_TRUE(fs::is_empty(dir.path()));
        }
    // glTF without Draco takes no Draco settings, so it does not check them.
    io::WriteOptions plain;
    plain.format_options.set(io::DracoSettings{.position_bits = 31});
    plain.format_options.set(io::GltfSettings{io::GltfSettings::Compression::kNone});
    EXPECT_NO_THROW(io::open_output(dir / "plain.glb", {}, plain));
    io::WriteOptions ends;
    ends.memory_budget_bytes = uint64_t{64} << 30;  // 30 bits' coding tables take about 4 GiB
    ends.format_options.set(
        io::DracoSettings{.position_bits = 30, .normal_bits = 2, .texcoord_bits = 1, .color_bits = 30, .level = 0});
    EXPECT_NO_THROW(io::open_output(dir / "ends.drc", {}, ends));
}

TEST(FormatOptions, HoldOneSetOfEachFormatsOptionsAndGiveDefaultsOtherwise) {
    io::WriteOptions o;
    EXPECT_EQ(o.format_options.get<io::DracoSettings>().position_bits, 14);
    EXPECT_EQ(o.format_options.get<io::GltfSettings>().compression, io::GltfSettings::Compression::kDraco);
    o.format_options.set(io::DracoSettings{.position_bits = 9});
    o.format_options.set(io::GltfSettings{io::GltfSettings::Compression::kMeshopt});
    o.format_options.set(io::DracoSettings{.normal_bits = 5});  // replaces the first
    const io::WriteOptions copy = o;
    const io::DracoSettings d = copy.format_options.get<io::DracoSettings>();
    EXPECT_EQ(d.position_bits, 14);
    EXPECT_EQ(d.normal_bits, 5);
    EXPECT_EQ(copy.format_options.get<io::GltfSettings>().compression, io::GltfSettings::Compression::kMeshopt);
}

TEST(DracoWriter, SettingsReachTheGltfWritersDracoEncoding) {
    // The Draco settings given for a .glb reach its KHR_draco_mesh_compression primitive: the
    // reader reports the primitive's quantization, and 11 bits move the coordinates of the
    // bunny (a 14-bit Draco decode, which 14 bits keep) within their bound.
    TempDir dir;
    Soup bunny = read_soup(fixture("bunny_from_draco.bin.stl"));
    double worst[2] = {0, 0};
    for (int i = 0; i < 2; ++i) {
        const int qp = i == 0 ? 14 : 11;
        SCOPED_TRACE(qp);
        io::WriteOptions o;
        o.format_options.set(io::DracoSettings{.position_bits = qp});
        write_soup(bunny, dir / "b.glb", o);
        io::MeshHeader h;
        Soup back = read_soup(dir / "b.glb", io::TriangleChunk::kDefaultCapacity, &h);
        EXPECT_NE(note(h, "draco").find("positions " + std::to_string(qp) + " bits"), std::string::npos)
            << note(h, "draco");
        worst[i] = expect_within_quantization_bound(bunny, back, qp);
    }
    EXPECT_GT(worst[1], worst[0]);
}

}  // namespace

namespace {

// The PLY header draco_decoder writes for `drc`: its vertex properties tell the attributes it
// decoded.
std::string draco_decoder_header(const std::string& drc, const std::string& ply) {
    draco_decoder_counts(drc, ply);
    const std::string text = slurp(ply);
    return text.substr(0, text.find("end_header"));
}

// A small mesh of random triangles with two named scalars: 'intensity' (ushort) and
// 'confidence' (float).
Mesh scalar_mesh() {
    Mesh m;
    m.header.channels.vertex_scalars = {{"intensity", io::ScalarType::kUInt16},
                                        {"confidence", io::ScalarType::kFloat32}};
    m.scalars.resize(2);
    std::mt19937 rng(11);
    for (int t = 0; t < 40; ++t)
        for (int k = 0; k < 3; ++k) {
            for (int a = 0; a < 3; ++a) m.xyz.push_back(float(rng() % 1000) / 8);
            m.scalars[0].push_back(double(rng() % 65536));
            m.scalars[1].push_back(double(float(rng() % 100000) / 100000.0f));
        }
    return m;
}

}  // namespace

TEST(DracoChannels, EveryChannelRoundTripsAndDracoDecoderReadsIt) {
    TempDir dir;
    {
        SCOPED_TRACE("colours: the cactus, uchar RGB");
        const Mesh ref = read_mesh(fixture("ply/cactus_vcolor.binary_le.ply"));
        EXPECT_TRUE(write_mesh(ref, dir / "c.drc").empty());
        const Mesh back = read_mesh(dir / "c.drc");
        EXPECT_EQ(back.header.channels.color, ref.header.channels.color);
        const ChannelErrors e = compare_meshes(ref, back, 1e-4);
        EXPECT_EQ(e.unmatched, 0u);
        EXPECT_EQ(e.color, 0.0);  // integers are stored as they are
        EXPECT_NE(draco_decoder_header(dir / "c.drc", dir / "c.ply").find("property uchar red"), std::string::npos);
    }
    {
        SCOPED_TRACE("normals: the elephant");
        const Mesh ref = read_mesh(fixture("drc/elephant_normals_sequential_cl0.drc"));
        write_mesh(ref, dir / "n.drc");
        const Mesh back = read_mesh(dir / "n.drc");
        EXPECT_TRUE(back.header.channels.normal);
        const ChannelErrors e = compare_meshes(ref, back, 2e-4);
        EXPECT_EQ(e.unmatched, 0u);
        EXPECT_LE(e.normal, 4.0 / 1023);  // --draco-qn 10: 2 steps of the octahedral square
        EXPECT_NE(draco_decoder_header(dir / "n.drc", dir / "n.ply").find("property float nx"), std::string::npos);
    }
    {
        SCOPED_TRACE("texture coordinates and normals with seams: BoxTextured");
        const Mesh ref = read_mesh(fixture("gltf/BoxTextured.glb"));
        write_mesh(ref, dir / "b.drc");
        const Mesh back = read_mesh(dir / "b.drc");
        EXPECT_EQ(back.header.channels.uv_sets, 1);
        EXPECT_TRUE(back.header.channels.normal);
        EXPECT_FALSE(back.header.channels.material);  // Draco has no materials
        EXPECT_EQ(back.header.vertex_count, 24u) << "the glTF's vertices, seams apart";
        const ChannelErrors e = compare_meshes(ref, back, 0.5 / 16383 * 1.0001);
        EXPECT_EQ(e.unmatched, 0u);
        EXPECT_LE(e.uv, 0.5 * 6 / 4095 * 1.0001 + 1e-6);  // --draco-qt 12 over their range, 6
        EXPECT_LE(e.normal, 4.0 / 1023);
        EXPECT_EQ(draco_decoder_counts(dir / "b.drc", dir / "b.ply").first, 24u);
    }
    {
        SCOPED_TRACE("named scalars: Draco generic attributes with 'name' metadata");
        const Mesh ref = scalar_mesh();
        write_mesh(ref, dir / "s.drc");
        const Mesh back = read_mesh(dir / "s.drc");
        ASSERT_EQ(back.header.channels.vertex_scalars, ref.header.channels.vertex_scalars);
        const ChannelErrors e = compare_meshes(ref, back, 0.5 * 125 / 16383 * 1.0001);
        EXPECT_EQ(e.unmatched, 0u);
        double intensity = 0, confidence = 0;
        Mesh only = ref;
        // Per channel: ushort exactly, float within --draco-qc 10 bits over its range (< 1).
        only.scalars = {ref.scalars[0], std::vector<double>(ref.scalars[1].size(), 0.0)};
        Mesh back_only = back;
        back_only.scalars = {back.scalars[0], std::vector<double>(back.scalars[1].size(), 0.0)};
        intensity = compare_meshes(only, back_only, 0.5 * 125 / 16383 * 1.0001).scalar;
        only.scalars = {ref.scalars[1]};
        back_only.scalars = {back.scalars[1]};
        confidence = compare_meshes(only, back_only, 0.5 * 125 / 16383 * 1.0001).scalar;
        EXPECT_EQ(intensity, 0.0);
        EXPECT_GT(confidence, 0.0);
        EXPECT_LE(confidence, 0.5 / 1023 * 1.0001);
        EXPECT_EQ(draco_decoder_counts(dir / "s.drc", dir / "s.ply").second, 40u);
    }
}

TEST(DracoChannels, QuantizationFlagsBoundTheirChannels) {
    // --draco-qn, --draco-qt and --draco-qc as draco_encoder's -qn, -qt and -qg: each bounds its
    // channel's error, and fewer bits give more.
    TempDir dir;
    const Mesh box = read_mesh(fixture("gltf/BoxTextured.glb"));
    const Mesh scalars = scalar_mesh();
    ChannelErrors coarse, fine;
    for (int bits : {6, 16}) {
        SCOPED_TRACE(bits);
        io::WriteOptions o;
        o.format_options.set(io::DracoSettings{.normal_bits = bits, .texcoord_bits = bits, .color_bits = bits});
        write_mesh(box, dir / "b.drc", o);
        write_mesh(scalars, dir / "s.drc", o);
        ChannelErrors e = compare_meshes(box, read_mesh(dir / "b.drc"), 0.5 / 16383 * 1.0001);
        Mesh s = scalars, back = read_mesh(dir / "s.drc");
        s.scalars.erase(s.scalars.begin());
        back.scalars.erase(back.scalars.begin());
        e.scalar = compare_meshes(s, back, 0.5 * 125 / 16383 * 1.0001).scalar;
        EXPECT_EQ(e.unmatched, 0u);
        const double steps = double((1 << bits) - 1);
        EXPECT_LE(e.uv, 0.5 * 6 / steps * 1.0001 + 1e-6);
        EXPECT_LE(e.normal, 4.0 / steps);
        EXPECT_LE(e.scalar, 0.5 / steps * 1.0001);
        (bits == 6 ? coarse : fine) = e;
    }
    EXPECT_GT(coarse.uv, 10 * fine.uv);
    EXPECT_GT(coarse.scalar, 10 * fine.scalar);
    EXPECT_GE(coarse.normal, fine.normal);  // the box's axis-aligned normals may stay exact
}
