// Reads a mesh through the installed io library and decimates it with the installed decimator:
// prints "<input triangles> <output triangles>". It includes every public entry header, so
// an installed header that includes one the install left out fails this build.
#include <meshstream/compare/metro.hpp>
#include <meshstream/compare/order.hpp>
#include <meshstream/compare/topology.hpp>
#include <meshstream/decimate/stream_decimator.hpp>
#include <meshstream/io/error.hpp>
#include <meshstream/io/format.hpp>
#include <meshstream/io/mesh_index.hpp>
#include <meshstream/io/read_indexed.hpp>
#include <meshstream/io/triangle_input.hpp>
#include <meshstream/sort/external_sort.hpp>
#if MESHSTREAM_WITH_DRACO
#include <meshstream/io/draco.hpp>
#endif
#if MESHSTREAM_WITH_GLTF
#include <meshstream/io/gltf.hpp>
#endif

#include <cstdio>

int main(int argc, char** argv) {
    if (argc != 2) return 2;
    meshstream::io::Input in = meshstream::io::open_input(argv[1]);
    meshstream::decimate::Options options;
    options.ratio = 0.5;
    meshstream::decimate::StreamDecimator decimator(options, in.reader->header().triangle_count);
    unsigned long long read = 0, written = 0;
    auto emit = [&](const meshstream::io::TriangleChunk& chunk) { written += chunk.size(); };
    meshstream::io::TriangleChunk chunk;
    while (in.reader->next(chunk)) {
        read += chunk.size();
        decimator.push(chunk, emit);
    }
    decimator.finish(emit);
    std::printf("%llu %llu\n", read, written);
    return 0;
}
