// Bench-only speed and quality reference (bench/decimate.sh): the in-core pipeline a user
// would write with meshoptimizer 1.2 (../shared/peers/meshoptimizer-1.2, built by
// bench/CMakeLists.txt, never linked into the product): read the whole mesh, weld exact
// duplicate positions (meshopt_generateVertexRemap), simplify to the target count, write.
// By default meshopt_simplifyWithUpdate, which moves the kept vertices to their quadric optimum
// as meshstream does; --plain calls meshopt_simplify (vertices stay at input positions).
// Prints one line "ref_meshopt: in N out M seconds S" on stderr.
//   ref_meshopt IN OUT --target N [--plain]
#include "io/error.hpp"
#include "io/format.hpp"

#include <meshoptimizer.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    using namespace meshstream;
    const bool plain = argc == 6 && std::string(argv[5]) == "--plain";
    if ((argc != 5 && !plain) || std::string(argv[3]) != "--target") {
        std::fprintf(stderr, "usage: ref_meshopt IN OUT --target TRIANGLES [--plain]\n");
        return 2;
    }
    size_t target = std::strtoull(argv[4], nullptr, 10);
    auto start = std::chrono::steady_clock::now();
    try {
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
