// Bench/docs helper: renders a mesh to PNG with a streaming z-buffer rasteriser (orthographic
// view, two-sided Lambert shading, optional wireframe; a mesh with vertex colours shows them,
// interpolated over each triangle), so docs/decimation.md can show the same model at several
// resolutions in the same frame. Two passes over the file: bounds, then
// triangles straight into the z-buffer; memory is the image only. PNG is written through zlib.
//   render_mesh IN OUT.png [--size W] [--view X,Y,Z] [--frame REF] [--wire]
// --frame REF: frame the picture with REF's bounding box (the full-resolution mesh), so all
// pictures of one model line up.
#include "io/error.hpp"
#include "io/format.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace {

using Vec = std::array<double, 3>;
Vec sub(Vec a, Vec b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec cross(Vec a, Vec b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
double dot(Vec a, Vec b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec normalize(Vec a) {
    double l = std::sqrt(dot(a, a));
    return l > 0 ? Vec{a[0] / l, a[1] / l, a[2] / l} : a;
}

meshstream::io::Bounds bounds_of(const std::string& path) {
    meshstream::io::Input in = meshstream::io::open_input(path);
    meshstream::io::TriangleChunk chunk;
    meshstream::io::Bounds b;
    b.min.fill(std::numeric_limits<float>::infinity());
    b.max.fill(-std::numeric_limits<float>::infinity());
    while (in.reader->next(chunk))
        for (size_t i = 0; i < chunk.xyz().size(); ++i) {
            float x = chunk.xyz()[i];
            if (!std::isfinite(x)) continue;
            b.min[i % 3] = std::min(b.min[i % 3], x);
            b.max[i % 3] = std::max(b.max[i % 3], x);
        }
    return b;
}

void put_chunk(std::FILE* f, const char* type, const std::vector<unsigned char>& data) {
    unsigned char len[4] = {uint8_t(data.size() >> 24), uint8_t(data.size() >> 16), uint8_t(data.size() >> 8),
                            uint8_t(data.size())};
    std::fwrite(len, 1, 4, f);
    uLong crc = crc32(0, reinterpret_cast<const Bytef*>(type), 4);
    if (!data.empty()) crc = crc32(crc, data.data(), uInt(data.size()));
    std::fwrite(type, 1, 4, f);
    if (!data.empty()) std::fwrite(data.data(), 1, data.size(), f);
    unsigned char c[4] = {uint8_t(crc >> 24), uint8_t(crc >> 16), uint8_t(crc >> 8), uint8_t(crc)};
    std::fwrite(c, 1, 4, f);
}

void write_png(const std::string& path, int w, int h, const std::vector<unsigned char>& rgb) {
    std::vector<unsigned char> raw;
    raw.reserve(size_t(h) * (3 * w + 1));
    for (int y = 0; y < h; ++y) {
        raw.push_back(0);  // filter: none
        raw.insert(raw.end(), &rgb[size_t(y) * 3 * w], &rgb[size_t(y) * 3 * w] + 3 * w);
    }
    uLongf size = compressBound(uLong(raw.size()));
    std::vector<unsigned char> z(size);
    if (compress2(z.data(), &size, raw.data(), uLong(raw.size()), 9) != Z_OK)
        throw meshstream::io::Error(path, "zlib compression failed");
    z.resize(size);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) throw meshstream::io::Error(path, "cannot create file");
    const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::fwrite(sig, 1, 8, f);
    std::vector<unsigned char> ihdr = {uint8_t(w >> 24),
                                       uint8_t(w >> 16),
                                       uint8_t(w >> 8),
                                       uint8_t(w),
                                       uint8_t(h >> 24),
                                       uint8_t(h >> 16),
                                       uint8_t(h >> 8),
                                       uint8_t(h),
                                       8,
                                       2,
                                       0,
                                       0,
                                       0};  // 8-bit RGB
    put_chunk(f, "IHDR", ihdr);
    put_chunk(f, "IDAT", z);
    put_chunk(f, "IEND", {});
    if (std::fclose(f) != 0) throw meshstream::io::Error(path, "write failed");
}

}  // namespace

int main(int argc, char** argv) {
    using namespace meshstream;
    std::string in_path, out_path, frame;
    int size = 640;
    Vec view = {0, 0, 1};
    bool wire = false;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--size" && i + 1 < argc)
            size = std::atoi(argv[++i]);
        else if (a == "--frame" && i + 1 < argc)
            frame = argv[++i];
        else if (a == "--wire")
            wire = true;
        else if (a == "--view" && i + 1 < argc) {
            if (std::sscanf(argv[++i], "%lf,%lf,%lf", &view[0], &view[1], &view[2]) != 3) return 2;
        } else if (in_path.empty())
            in_path = a;
        else if (out_path.empty())
            out_path = a;
        else {
            std::fprintf(stderr, "usage: render_mesh IN OUT.png [--size W] [--view X,Y,Z] [--frame REF] [--wire]\n");
            return 2;
        }
    }
    if (out_path.empty() || size < 16) {
        std::fprintf(stderr, "usage: render_mesh IN OUT.png [--size W] [--view X,Y,Z] [--frame REF] [--wire]\n");
        return 2;
    }
    try {
        io::Bounds b = bounds_of(frame.empty() ? in_path : frame);
        Vec center = {(b.min[0] + b.max[0]) / 2.0, (b.min[1] + b.max[1]) / 2.0, (b.min[2] + b.max[2]) / 2.0};
        double radius = 0.5 * std::sqrt(dot(sub(Vec{b.max[0], b.max[1], b.max[2]}, Vec{b.min[0], b.min[1], b.min[2]}),
                                            sub(Vec{b.max[0], b.max[1], b.max[2]}, Vec{b.min[0], b.min[1], b.min[2]})));
        Vec forward = normalize(view);  // from the model towards the eye
        Vec up = std::fabs(forward[1]) > 0.9 ? Vec{0, 0, 1} : Vec{0, 1, 0};
        Vec right = normalize(cross(up, forward));
        up = cross(forward, right);
        Vec light = normalize(Vec{forward[0] + 0.4 * right[0] + 0.5 * up[0], forward[1] + 0.4 * right[1] + 0.5 * up[1],
                                  forward[2] + 0.4 * right[2] + 0.5 * up[2]});
        const int w = size, h = size;
        double scale = 0.95 * size / (2 * radius);
        std::vector<float> depth(size_t(w) * h, -std::numeric_limits<float>::infinity());
        std::vector<unsigned char> rgb(size_t(w) * h * 3, 255);

        io::Input in = io::open_input(in_path);
        io::Channels colour_only;
        colour_only.color = in.reader->header().channels.color;
        io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, colour_only);
        while (in.reader->next(chunk)) {
            auto xyz = chunk.xyz();
            for (size_t t = 0; t < chunk.size(); ++t) {
                Vec p[3];
                double sx[3], sy[3], sz[3];
                for (int c = 0; c < 3; ++c) {
                    p[c] = {xyz[9 * t + 3 * c], xyz[9 * t + 3 * c + 1], xyz[9 * t + 3 * c + 2]};
                    Vec q = sub(p[c], center);
                    sx[c] = w / 2.0 + scale * dot(q, right);
                    sy[c] = h / 2.0 - scale * dot(q, up);
                    sz[c] = dot(q, forward);
                }
                Vec n = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])));
                double shade = 0.25 + 0.75 * std::fabs(dot(n, light));
                double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
                if (std::fabs(area) < 1e-12 || !std::isfinite(area)) continue;
                int x0 = std::max(0, int(std::floor(std::min({sx[0], sx[1], sx[2]}))));
                int x1 = std::min(w - 1, int(std::ceil(std::max({sx[0], sx[1], sx[2]}))));
                int y0 = std::max(0, int(std::floor(std::min({sy[0], sy[1], sy[2]}))));
                int y1 = std::min(h - 1, int(std::ceil(std::max({sy[0], sy[1], sy[2]}))));
                // Edge lengths in pixels turn barycentrics into distances to the edges.
                double len[3];
                for (int e = 0; e < 3; ++e)
                    len[e] = std::hypot(sx[(e + 2) % 3] - sx[(e + 1) % 3], sy[(e + 2) % 3] - sy[(e + 1) % 3]);
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x) {
                        double px = x + 0.5, py = y + 0.5;
                        double l0 = ((sx[1] - px) * (sy[2] - py) - (sx[2] - px) * (sy[1] - py)) / area;
                        double l1 = ((sx[2] - px) * (sy[0] - py) - (sx[0] - px) * (sy[2] - py)) / area;
                        double l2 = 1 - l0 - l1;
                        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
                        float z = float(l0 * sz[0] + l1 * sz[1] + l2 * sz[2]);
                        size_t at = size_t(y) * w + x;
                        if (z <= depth[at]) continue;
                        depth[at] = z;
                        double s = shade;
                        if (wire) {
                            double dist = std::min({l0 * std::fabs(area) / len[0], l1 * std::fabs(area) / len[1],
                                                    l2 * std::fabs(area) / len[2]});
                            if (dist < 0.7) s *= 0.45;
                        }
                        double base[3] = {235, 215, 180};
                        if (const float* c = chunk.color_at(t))
                            for (int k = 0; k < 3; ++k) base[k] = 255 * (l0 * c[k] + l1 * c[4 + k] + l2 * c[8 + k]);
                        for (int k = 0; k < 3; ++k) rgb[3 * at + k] = uint8_t(std::clamp(s * base[k], 0.0, 255.0));
                    }
            }
        }
        write_png(out_path, w, h, rgb);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "render_mesh: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
