// Bench-only speed and quality reference (bench/decimate.sh, bench/attributes.sh): the in-core
// pipeline a user would write with meshoptimizer 1.2 (../shared/peers/meshoptimizer-1.2, built by
// bench/CMakeLists.txt, never linked into the product): read the whole mesh, weld exact
// duplicate positions (meshopt_generateVertexRemap), simplify to the target count, write.
// By default meshopt_simplifyWithUpdate, which moves the kept vertices to their quadric optimum
// as meshstream does; --plain calls meshopt_simplify (vertices stay at input positions).
// --attributes reads the input's colours and normals too and welds corners by position and
// those values (so colour and normal seams stay split, as meshoptimizer's simplifier expects),
// simplifies with meshopt_simplifyWithUpdate rating colour RGB (0..1) and normals as attributes
// of weight 1, and writes the updated values (colours clamped to 0..1, normals normalized); an
// alpha channel is welded and carried but not rated. Other channels (texture coordinates,
// scalars, materials) are not read. The output format must hold the channels read (PLY does).
// Prints one line "ref_meshopt: in N out M seconds S" on stderr.
//   ref_meshopt IN OUT --target N [--plain | --attributes]
#include "io/error.hpp"
#include "io/format.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace meshstream;

// --attributes: one welded vertex as floats: x y z, then the rated values (colour RGB, then
// normal xyz, as present), then the unrated alpha when the colour has one.
struct VertexLayout {
    io::Channels channels;  // colour and normal, as the input has them
    size_t color = 0, normal = 0, alpha = 0;  // offsets in floats (0: absent; position is at 0)
    size_t rated = 0;                         // values rated as attributes, from offset 3
    size_t stride = 3;                        // floats per vertex

    explicit VertexLayout(const io::Channels& in) {
        channels.color = in.color;
        channels.normal = in.normal;
        if (channels.color) color = stride, stride += 3;
        if (channels.normal) normal = stride, stride += 3;
        rated = stride - 3;
        if (channels.color && channels.color->alpha) alpha = stride++;
    }
};

// The input's corners as records of layout.stride floats (the input is released on return).
std::vector<float> read_corners(io::Input in, const VertexLayout& layout) {
    const size_t stride = layout.stride;
    std::vector<float> soup;
    if (auto n = in.reader->triangle_count()) soup.reserve(3 * stride * *n);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, layout.channels);
    float corner[64];
    while (in.reader->next(chunk)) {
        for (size_t i = 0; i < chunk.size(); ++i)
            for (size_t k = 0; k < 3; ++k) {
                std::memcpy(corner, &chunk.xyz()[9 * i + 3 * k], 3 * sizeof(float));
                if (layout.color) std::memcpy(corner + layout.color, chunk.color_at(i) + 4 * k, 3 * sizeof(float));
                if (layout.normal) std::memcpy(corner + layout.normal, chunk.normal_at(i) + 3 * k, 3 * sizeof(float));
                if (layout.alpha) corner[layout.alpha] = chunk.color_at(i)[4 * k + 3];
                // -0 + 0 = +0: the weld compares bytes, and -0 equals +0.
                for (size_t f = 0; f < stride; ++f) corner[f] += 0.0f;
                soup.insert(soup.end(), corner, corner + stride);
            }
    }
    return soup;
}

// Returns the output triangle count (and the input's in `in_triangles`); writes OUT.
size_t simplify_with_attributes(const char* in_path, const char* out_path, size_t target, size_t& in_triangles) {
    io::Input in = io::open_input(in_path);
    const VertexLayout layout(in.reader->header().channels);
    if (layout.rated == 0)
        throw std::runtime_error(std::string(in_path) + ": --attributes: the input has neither colours nor normals");
    const size_t stride = layout.stride;
    std::vector<float> soup = read_corners(std::move(in), layout);
    const size_t corners = soup.size() / stride;
    in_triangles = corners / 3;
    std::vector<unsigned int> remap(corners);
    size_t vertex_count =
        meshopt_generateVertexRemap(remap.data(), nullptr, corners, soup.data(), corners, stride * sizeof(float));
    std::vector<float> vertices(stride * vertex_count);
    meshopt_remapVertexBuffer(vertices.data(), soup.data(), corners, stride * sizeof(float), remap.data());
    soup = {};
    std::vector<unsigned int> indices(std::move(remap));  // the unindexed soup's index buffer is the remap
    // Every rated value weight 1 (colours in 0..1, unit normals); target_error 1 (the whole mesh
    // extent): stop on the count, not on an error bound.
    const std::vector<float> weights(layout.rated, 1.0f);
    float error = 0;
    size_t n = meshopt_simplifyWithUpdate(indices.data(), indices.size(), vertices.data(), vertex_count,
                                          stride * sizeof(float), vertices.data() + 3, stride * sizeof(float),
                                          weights.data(), layout.rated, nullptr, 3 * target, 1.0f, 0, &error);

    io::WriteOptions options;
    options.channels = layout.channels;
    options.triangle_count = n / 3;
    const io::Channels kept = io::writable_channels(io::output_format(out_path, ""), layout.channels, options);
    if (const std::string lost = io::describe_missing(layout.channels, kept); !lost.empty())
        throw std::runtime_error(std::string(out_path) + ": --attributes: the output format would drop " + lost);
    io::Output o = io::open_output(out_path, "", options);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, layout.channels);
    for (size_t i = 0; i < n; i += 3) {
        float* t = chunk.push_slot();
        const size_t slot = chunk.size() - 1;
        for (size_t c = 0; c < 3; ++c) {
            const float* v = &vertices[stride * size_t(indices[i + c])];
            std::memcpy(t + 3 * c, v, 3 * sizeof(float));
            if (layout.color) {
                float* rgba = chunk.color_at(slot) + 4 * c;
                for (size_t j = 0; j < 3; ++j) rgba[j] = std::clamp(v[layout.color + j], 0.0f, 1.0f);
                rgba[3] = layout.alpha ? v[layout.alpha] : 1.0f;
            }
            if (layout.normal) {
                const float* nv = v + layout.normal;
                float* out = chunk.normal_at(slot) + 3 * c;
                float len = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
                for (size_t j = 0; j < 3; ++j) out[j] = len > 0 ? nv[j] / len : 0.0f;  // a zero one stays zero
            }
        }
        if (chunk.full()) {
            o.write(chunk);
            chunk.clear();
        }
    }
    if (!chunk.empty()) o.write(chunk);
    o.finish();
    return n / 3;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace meshstream;
    const bool plain = argc == 6 && std::string(argv[5]) == "--plain";
    const bool attributes = argc == 6 && std::string(argv[5]) == "--attributes";
    if ((argc != 5 && !plain && !attributes) || std::string(argv[3]) != "--target") {
        std::fprintf(stderr, "usage: ref_meshopt IN OUT --target TRIANGLES [--plain | --attributes]\n");
        return 2;
    }
    size_t target = std::strtoull(argv[4], nullptr, 10);
    auto start = std::chrono::steady_clock::now();
    try {
        if (attributes) {
            size_t in_triangles = 0;
            size_t out_triangles = simplify_with_attributes(argv[1], argv[2], target, in_triangles);
            double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            std::fprintf(stderr, "ref_meshopt: in %zu out %zu seconds %.3f\n", in_triangles, out_triangles, seconds);
            return 0;
        }
        std::vector<float> soup;
        {
            io::Input in = io::open_input(argv[1]);
            if (auto n = in.reader->triangle_count()) soup.reserve(9 * *n);
            io::TriangleChunk chunk;
            while (in.reader->next(chunk)) soup.insert(soup.end(), chunk.xyz().begin(), chunk.xyz().end());
        }
        size_t corners = soup.size() / 3;
        std::vector<unsigned int> remap(corners);
        size_t vertex_count =
            meshopt_generateVertexRemap(remap.data(), nullptr, corners, soup.data(), corners, 3 * sizeof(float));
        std::vector<float> vertices(3 * vertex_count);
        meshopt_remapVertexBuffer(vertices.data(), soup.data(), corners, 3 * sizeof(float), remap.data());
        soup = {};
        std::vector<unsigned int> indices(remap);  // the unindexed soup's index buffer is the remap
        remap = {};
        float error = 0;
        // target_error 1 (the whole mesh extent): stop on the count, not on an error bound.
        size_t n = 0;
        std::vector<unsigned int> out;
        if (plain) {
            out.resize(indices.size());
            n = meshopt_simplify(out.data(), indices.data(), indices.size(), vertices.data(), vertex_count,
                                 3 * sizeof(float), 3 * target, 1.0f, 0, &error);
        } else {
            n = meshopt_simplifyWithUpdate(indices.data(), indices.size(), vertices.data(), vertex_count,
                                           3 * sizeof(float), nullptr, 0, nullptr, 0, nullptr, 3 * target, 1.0f, 0,
                                           &error);
            out.swap(indices);
        }
        io::Output o = io::open_output(argv[2], "", {});
        io::TriangleChunk chunk;
        for (size_t i = 0; i < n; i += 3) {
            float* t = chunk.push_slot();
            for (int c = 0; c < 3; ++c) std::memcpy(t + 3 * c, &vertices[3 * size_t(out[i + c])], 3 * sizeof(float));
            if (chunk.full()) {
                o.write(chunk);
                chunk.clear();
            }
        }
        if (!chunk.empty()) o.write(chunk);
        o.finish();
        double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::fprintf(stderr, "ref_meshopt: in %zu out %zu seconds %.3f\n", corners / 3, n / 3, seconds);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ref_meshopt: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
