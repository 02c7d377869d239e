// decimate/attributes.hpp and attribute_quadric.hpp: the corner vector of a stream's channels and
// the attribute quadric.
#include "decimate/attributes.hpp"
#include "decimate/attribute_quadric.hpp"
#include "io/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

using namespace meshstream;
using decimate::AttributeLayout;
using decimate::AttributeQuadric;
using decimate::AttributeWeights;

// a(x) = 0.3x − 0.2y + 0.05z + 0.1 and b(x) = −x + 2y + 0.5, sampled at a triangle's corners.
void linear_values(const double p[3], float out[2]) {
    out[0] = float(0.3 * p[0] - 0.2 * p[1] + 0.05 * p[2] + 0.1);
    out[1] = float(-p[0] + 2 * p[1] + 0.5);
}

// Two triangles of one plane, quadrics summed: an interior vertex's neighbourhood.
std::vector<double> two_triangle_quadric(const double omega[2]) {
    const double p[4][3] = {{0, 0, 0}, {1, 0, 0.5}, {1, 1, 0.5}, {0, 1, 0}};
    float a[4][2];
    for (int i = 0; i < 4; ++i) linear_values(p[i], a[i]);
    std::vector<double> q(AttributeQuadric::size(2)), r(AttributeQuadric::size(2));
    AttributeQuadric::from_triangle(q.data(), p[0], p[1], p[2], a[0], a[1], a[2], 2, omega);
    AttributeQuadric::from_triangle(r.data(), p[0], p[2], p[3], a[0], a[2], a[3], 2, omega);
    AttributeQuadric::add(q.data(), r.data(), 2);
    return q;
}

TEST(AttributeQuadric, AreaIsTheTrianglesArea) {
    const double omega[2] = {1, 1};
    const std::vector<double> q = two_triangle_quadric(omega);
    EXPECT_NEAR(AttributeQuadric::area(q.data()), std::sqrt(1.25), 1e-12);  // a 1 × √1.25 rectangle
}

TEST(AttributeQuadric, ALinearFieldIsReproducedAnywhereOnItsPlane) {
    const double omega[2] = {1, 1};
    const std::vector<double> q = two_triangle_quadric(omega);
    for (const double x : {0.0, 0.25, 0.9, 3.0}) {
        const double at[3] = {x, 1 - 0.5 * x, 0.5 * x};  // on the plane z = x/2
        float expect[2], got[2];
        linear_values(at, expect);
        const float fallback[2] = {-7, -7};
        AttributeQuadric::values(q.data(), 2, at, fallback, got);
        EXPECT_NEAR(got[0], expect[0], 1e-5);
        EXPECT_NEAR(got[1], expect[1], 1e-5);
        // The values minimize the error, which is then 0 (within round-off).
        EXPECT_NEAR(AttributeQuadric::error(q.data(), 2, omega, at, got), 0, 1e-9);
        EXPECT_NEAR(AttributeQuadric::reduced(q.data(), 2, omega).error(at), 0, 1e-9);
    }
}

TEST(AttributeQuadric, FixedValuesCostAreaTimesWeightTimesSquaredDifference) {
    const double omega[2] = {4, 0};  // weight 2 on a, 0 on b
    const std::vector<double> q = two_triangle_quadric(omega);
    const double at[3] = {0.5, 0.5, 0.25};
    float v[2];
    linear_values(at, v);
    v[0] += 0.1f;  // a off by 0.1
    v[1] += 5.0f;  // b off by a lot, but weighs nothing
    const double area = std::sqrt(1.25);
    EXPECT_NEAR(AttributeQuadric::error(q.data(), 2, omega, at, v), area * 4 * 0.01, 1e-6);
}

TEST(AttributeQuadric, ANonLinearFieldCostsAtTheMeanOfTheInterpolations) {
    // Two triangles disagree about the value at their shared corner's far side: a crease in the
    // field. The optimal value at the shared corner is their area-weighted mean and costs > 0.
    const double omega[1] = {1};
    const double p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}};
    const float a0 = 0, a1 = 1, a2 = 0, a3 = 0;  // a ramp on one side, flat on the other
    std::vector<double> q(AttributeQuadric::size(1)), r(AttributeQuadric::size(1));
    AttributeQuadric::from_triangle(q.data(), p[0], p[1], p[2], &a0, &a1, &a2, 1, omega);
    AttributeQuadric::from_triangle(r.data(), p[0], p[2], p[3], &a0, &a2, &a3, 1, omega);
    AttributeQuadric::add(q.data(), r.data(), 1);
    const double at[3] = {0.5, 0, 0};  // the ramp says 0.5, the flat side (extended) 0
    float v = 0;
    const float fallback = 0;
    AttributeQuadric::values(q.data(), 1, at, &fallback, &v);
    EXPECT_NEAR(v, 0.25, 1e-6);  // equal areas
    // Σ A (interp − 0.25)² = 0.5·0.0625 + 0.5·0.0625.
    EXPECT_NEAR(AttributeQuadric::reduced(q.data(), 1, omega).error(at), 0.0625, 1e-9);
}

TEST(AttributeQuadric, ADegenerateTriangleAddsNothing) {
    const double omega[1] = {1};
    const double p0[3] = {0, 0, 0}, p1[3] = {1, 1, 1}, p2[3] = {2, 2, 2};
    const float a0 = 0, a1 = 1, a2 = 5;
    std::vector<double> q(AttributeQuadric::size(1), 1.0);
    AttributeQuadric::from_triangle(q.data(), p0, p1, p2, &a0, &a1, &a2, 1, omega);
    for (double x : q) EXPECT_EQ(x, 0);
}

io::Channels every_channel() {
    io::Channels c;
    c.normal = true;
    c.color = io::ColorFormat{io::ScalarType::kUInt8, true};
    c.uv_sets = 2;
    c.vertex_scalars = {{"intensity", io::ScalarType::kFloat32}, {"confidence", io::ScalarType::kUInt8}};
    c.material = true;
    c.face_scalars = {{"label", io::ScalarType::kInt32}};
    c.vertex_id = true;
    return c;
}

TEST(AttributeLayout, MapsEveryPerCornerChannelToOneVector) {
    AttributeWeights w;
    w.normal = 0.5;
    w.color = 2;
    w.uv = 1;
    w.scalars = {{"confidence", 3}};
    const AttributeLayout layout(every_channel(), w);
    EXPECT_EQ(layout.size(), 3 + 4 + 2 * 2 + 2);
    EXPECT_TRUE(layout.any());
    EXPECT_TRUE(layout.weighted());
    EXPECT_EQ(layout.face_scalar_count(), 1u);
    const std::vector<double> expect = {0.25, 0.25, 0.25, 4, 4, 4, 4, 1, 1, 1, 1, 0, 9};
    EXPECT_EQ(layout.omega(), expect);  // weights squared; 'intensity' not named: 0
    EXPECT_EQ(layout.channels(), every_channel());
}

TEST(AttributeLayout, GatherThenScatterRoundTripsNormalizingNormalsAndClampingColours) {
    const AttributeLayout layout(every_channel(), {});
    io::TriangleChunk in(4, every_channel()), out(4, every_channel());
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::copy(tri, tri + 9, in.push_slot());
    out.push_slot();
    for (int k = 0; k < 3; ++k) {
        float* n = in.normal_at(0) + 3 * k;
        n[0] = 0, n[1] = 0, n[2] = 2.0f;  // not unit length
        float* c = in.color_at(0) + 4 * k;
        c[0] = 0.25f, c[1] = 1.5f, c[2] = -0.5f, c[3] = 0.5f;
        in.uv_at(0, 0)[2 * k] = 0.1f * float(k);
        in.uv_at(0, 1)[2 * k + 1] = -3.0f;
        in.vertex_scalar_at(0, 0)[k] = 42.5;
        in.vertex_scalar_at(0, 1)[k] = 7;
    }
    float v[13];
    for (int k = 0; k < 3; ++k) {
        layout.gather(in, 0, k, v);
        layout.scatter(v, out, 0, k);
    }
    for (int k = 0; k < 3; ++k) {
        EXPECT_FLOAT_EQ(out.normal_at(0)[3 * k + 2], 1.0f);
        EXPECT_FLOAT_EQ(out.color_at(0)[4 * k + 0], 0.25f);
        EXPECT_FLOAT_EQ(out.color_at(0)[4 * k + 1], 1.0f);
        EXPECT_FLOAT_EQ(out.color_at(0)[4 * k + 2], 0.0f);
        EXPECT_FLOAT_EQ(out.color_at(0)[4 * k + 3], 0.5f);
        EXPECT_FLOAT_EQ(out.uv_at(0, 0)[2 * k], 0.1f * float(k));
        EXPECT_FLOAT_EQ(out.uv_at(0, 1)[2 * k + 1], -3.0f);
        EXPECT_EQ(out.vertex_scalar_at(0, 0)[k], 42.5);
        EXPECT_EQ(out.vertex_scalar_at(0, 1)[k], 7);
    }
}

TEST(AttributeLayout, PositionsOnlyCarriesNothing) {
    const AttributeLayout layout(io::Channels::ids_only(), {});
    EXPECT_EQ(layout.size(), 0);
    EXPECT_FALSE(layout.any());
    EXPECT_FALSE(layout.weighted());
}

TEST(AttributeLayout, RefusesWeightsForMissingScalarsAndBadNumbers) {
    auto refused = [](const AttributeWeights& weights, const std::string& message) {
        try {
            AttributeLayout layout(every_channel(), weights);
            ADD_FAILURE() << "accepted: " << message;
        } catch (const io::OptionError& e) {
            EXPECT_EQ(e.setting(), io::Setting::kWeights);
            EXPECT_EQ(std::string(e.what()), message);
        }
    };
    AttributeWeights w;
    w.scalars = {{"temperature", 1}};
    refused(w, "no vertex scalar 'temperature' to weigh");
    AttributeWeights negative;
    negative.color = -1;
    refused(negative, "attribute weight of colours must be a finite number >= 0, got -1");
    AttributeWeights nan;
    nan.normal = std::nan("");
    refused(nan, "attribute weight of normals must be a finite number >= 0, got nan");
}

TEST(AttributeLayout, ChunksWithoutAChannelDoNotCarryIt) {
    const AttributeLayout layout(every_channel(), {});
    EXPECT_TRUE(layout.carried_by(every_channel()));
    io::Channels fewer = every_channel();
    fewer.uv_sets = 1;
    EXPECT_FALSE(layout.carried_by(fewer));
    fewer = every_channel();
    fewer.material = false;
    EXPECT_FALSE(layout.carried_by(fewer));
}

}  // namespace
