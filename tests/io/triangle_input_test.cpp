// io::TriangleInput, the read loop every command shares: its three policies, the counts it
// keeps, the header's promise checked at the end, and channels kept aligned when it drops.
#include "io/triangle_input.hpp"

#include "io/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace {

using namespace meshstream;

// Hands out `tris` (9 floats each, a material index each) `per_call` at a time, with a
// header promising `promised` triangles.
class ListReader final : public io::Reader {
public:
    ListReader(std::vector<float> tris, std::optional<uint64_t> promised, size_t per_call)
        : tris_(std::move(tris)), per_call_(per_call) {
        header_.triangle_count = promised;
        header_.channels.material = true;
    }
    bool next(io::TriangleChunk& chunk) override {
        chunk.clear();
        while (!chunk.full() && chunk.size() < per_call_ && pos_ < tris_.size() / 9) {
            float* slot = chunk.push_slot();
            for (int k = 0; k < 9; ++k) slot[k] = tris_[9 * pos_ + k];
            if (uint32_t* m = chunk.material_at(chunk.size() - 1)) *m = static_cast<uint32_t>(pos_);
            ++pos_;
        }
        return !chunk.empty();
    }

private:
    std::vector<float> tris_;
    size_t per_call_;
    size_t pos_ = 0;
};

const float kNan = std::numeric_limits<float>::quiet_NaN();

// Triangles 0..5: good, NaN, good, degenerate (-0 vs +0), good, degenerate.
std::vector<float> mixed() {
    return {0,     0, 0, 1,    0, 0, 0, 1, 0,  //
            0,     0, 0, kNan, 0, 0, 0, 1, 0,  //
            1,     0, 0, 2,    0, 0, 1, 1, 0,  //
            -0.0f, 0, 0, 0,    0, 0, 0, 1, 0,  //
            2,     0, 0, 3,    0, 0, 2, 1, 0,  //
            5,     5, 5, 5,    5, 5, 5, 5, 5};
}

io::TriangleInput loop_over(std::vector<float> tris, std::optional<uint64_t> promised, io::BadTriangles policy,
                            size_t per_call = 100) {
    return io::TriangleInput(std::make_unique<ListReader>(std::move(tris), promised, per_call), "mem.stl", policy);
}

// Reads everything; returns the material index (= input ordinal) of each triangle passed on.
std::vector<uint32_t> drain(io::TriangleInput& in, size_t capacity = 4) {
    io::Channels channels;
    channels.material = true;
    io::TriangleChunk chunk(capacity, channels);
    std::vector<uint32_t> ordinals;
    while (in.next(chunk)) {
        EXPECT_FALSE(chunk.empty());
        for (size_t i = 0; i < chunk.size(); ++i) ordinals.push_back(*chunk.material_at(i));
    }
    return ordinals;
}

TEST(TriangleInput, KeepPassesEveryTriangleAsRead) {
    io::TriangleInput in = loop_over(mixed(), 6, io::BadTriangles::kKeep);
    EXPECT_EQ(drain(in), (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(in.count().read, 6u);
    EXPECT_EQ(in.count().dropped, 0u);
    EXPECT_TRUE(in.at_end());
}

TEST(TriangleInput, DropCountsEachKindAndKeepsChannelsAligned) {
    for (size_t per_call : {1, 2, 100}) {
        io::TriangleInput in = loop_over(mixed(), 6, io::BadTriangles::kDrop, per_call);
        EXPECT_EQ(drain(in, 3), (std::vector<uint32_t>{0, 2, 4})) << per_call;
        EXPECT_EQ(in.non_finite(), 1u);
        EXPECT_EQ(in.degenerate(), 2u);
        EXPECT_EQ(in.count().read, 6u);
        EXPECT_EQ(in.count().dropped, 3u);
        EXPECT_EQ(in.count().passed(), 3u);
    }
}

TEST(TriangleInput, ChunksThatLoseEveryTriangleAreNotHandedOut) {
    // One triangle per reader call: the NaN and degenerate ones leave empty chunks, which
    // next() reads past instead of returning (a consumer never sees an empty chunk).
    io::TriangleInput in = loop_over(mixed(), 6, io::BadTriangles::kDrop, 1);
    io::Channels channels;
    channels.material = true;
    io::TriangleChunk chunk(8, channels);
    int calls = 0;
    while (in.next(chunk)) {
        ASSERT_EQ(chunk.size(), 1u);
        ++calls;
    }
    EXPECT_EQ(calls, 3);
}

TEST(TriangleInput, RefuseNamesTheFileAndTheOrdinal) {
    io::TriangleInput nan = loop_over(mixed(), 6, io::BadTriangles::kRefuse);
    try {
        drain(nan);
        FAIL() << "no error";
    } catch (const io::Error& e) {
        EXPECT_STREQ(e.what(), "mem.stl: triangle 2 has a NaN or infinite coordinate (strict mode)");
    }
    const std::vector<float> all = mixed();
    std::vector<float> degenerate(all.begin() + 27, all.end());  // from triangle 3 on
    io::TriangleInput deg = loop_over(degenerate, 3, io::BadTriangles::kRefuse, 1);
    try {
        drain(deg);
        FAIL() << "no error";
    } catch (const io::Error& e) {
        EXPECT_STREQ(e.what(), "mem.stl: triangle 1 is degenerate (two corners at the same position) (strict mode)");
    }
}

TEST(TriangleInput, ABrokenPromiseIsAnErrorAtTheEnd) {
    for (uint64_t promised : {5, 7}) {
        io::TriangleInput in = loop_over(mixed(), promised, io::BadTriangles::kKeep);
        try {
            drain(in);
            FAIL() << promised;
        } catch (const io::Error& e) {
            EXPECT_EQ(std::string(e.what()),
                      "mem.stl: header promises " + std::to_string(promised) + " triangles, read 6");
        }
    }
    io::TriangleInput unpromised = loop_over(mixed(), std::nullopt, io::BadTriangles::kKeep);
    EXPECT_EQ(drain(unpromised).size(), 6u);
}

TEST(TriangleInput, UsableCountFollowsTheDrops) {
    io::InputCount count{100};
    EXPECT_EQ(count.usable(), 100u);
    count.read = 10;
    count.dropped = 4;
    EXPECT_EQ(count.usable(), 96u);
    EXPECT_EQ(count.passed(), 6u);
    EXPECT_EQ(io::InputCount{}.usable(), std::nullopt);
}

TEST(TriangleInput, FaultOfOneTriangle) {
    const float good[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const float sliver[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};  // zero area, three distinct corners: kept
    const float inf[9] = {0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::infinity(), 0};
    const float repeated[9] = {0, 0, 0, 1, 0, 0, 1, 0, 0};
    EXPECT_EQ(io::triangle_fault(good), io::TriangleFault::kNone);
    EXPECT_EQ(io::triangle_fault(sliver), io::TriangleFault::kNone);
    EXPECT_EQ(io::triangle_fault(inf), io::TriangleFault::kNonFinite);
    EXPECT_EQ(io::triangle_fault(repeated), io::TriangleFault::kDegenerate);
}

}  // namespace
