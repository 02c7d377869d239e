// meshstream-gen: synthetic test meshes of any size for tests and bench/. Marching cubes
// (Lorensen & Cline 1987) over an implicit solid — a gyroid network with bumps, clipped to a
// ball, with random phases from --seed — marched slab by slab along z, so the triangle soup
// comes out approximately sorted along z like a scanner pipeline's. --holes removes triangles
// inside random spheres (scan occlusions); --touching-holes keeps, inside the same spheres, the
// triangles of every other grid cell (a 3D checkerboard): cells that share a grid edge keep the
// surface vertex on it, so the patches' boundary loops touch at shared vertices, as hand-made
// and CAD-exported low-poly models' do; --hole-chains removes single cells along diagonal
// chains all over the surface, small holes whose loops touch where chained cells share a grid
// edge (a long boundary, as a low-poly model's); --shuffle writes the triangles in random order,
// out of core (random buckets in temporary files, each shuffled in memory). --color gives every
// corner an 8-bit RGB colour that is a function of its position (colour_at): smooth bands, and
// one sharp border (a plane across the solid) where warm colours meet cool ones, so welded
// corners agree and attribute-aware tools have both kinds of detail to keep.
//
// The case table is derived at start-up rather than copied: on each cube face the iso-line
// cuts off every maximal run of positive corners (so a face with diagonal corners separates
// the positive ones, the same rule seen from both cells sharing the face, hence watertight),
// the face segments chain into loops, and each loop becomes a fan. Edge vertices are
// interpolated from the edge's lower corner, so neighbouring cells produce bit-identical
// positions and exact welding recovers a closed manifold (before --holes), except where float
// rounding lands two edge vertices on one position (a few edges at some sizes: 4 at 100 k).
//
// Memory: the triangles of the bands of 4 slabs in flight (2 per worker thread waiting, one per
// worker being marched, one being written), which grow with the triangles per slab: measured
// 43 MB for 10 M and 150 MB for 50 M triangles with two threads (28 and 94 MB with one); the
// grid planes are small beside them (n ≈ 1200 for 50 M triangles: 12 MB). --shuffle adds one
// bucket of at most 128 MiB, shuffled in memory.
#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/format.hpp"
#include "io/random.hpp"
#include "tools/cli_checks.hpp"
#include "tools/help.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <numbers>
#include <thread>
#include <vector>

namespace meshstream::tools {
namespace {

using Rng = io::SplitMix64;  // seeded and passed in

// ---- The case table -------------------------------------------------------------------------

struct Edge {
    int corner;  // lower corner (bit a clear)
    int axis;
};

struct CaseTable {
    std::array<Edge, 12> edges;
    std::array<std::vector<std::array<uint8_t, 3>>, 256> triangles;  // edge indices, outward winding
};

int edge_index(const std::array<Edge, 12>& edges, int c0, int c1) {
    int lo = std::min(c0, c1), axis = std::countr_zero(unsigned(c0 ^ c1));
    for (int e = 0; e < 12; ++e)
        if (edges[e].corner == lo && edges[e].axis == axis) return e;
    return -1;
}

CaseTable build_case_table() {
    CaseTable table;
    int n = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (int c = 0; c < 8; ++c)
            if (!(c & (1 << axis))) table.edges[n++] = {c, axis};

    // Face corners counter-clockwise seen from outside: in the (u, v) = (a+1, a+2) plane the
    // order (0,0) (1,0) (1,1) (0,1) is counter-clockwise around +a; reversed for the -a face.
    std::array<std::array<int, 4>, 6> faces;
    for (int a = 0; a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
            int u = 1 << ((a + 1) % 3), v = 1 << ((a + 2) % 3), base = side ? 1 << a : 0;
            std::array<int, 4> q = {base, base | u, base | u | v, base | v};
            if (!side) std::swap(q[1], q[3]);
            faces[2 * a + side] = q;
        }

    for (int cube = 0; cube < 256; ++cube) {
        auto positive = [&](int c) { return (cube >> c) & 1; };
        std::array<int, 12> next;
        next.fill(-1);
        for (const auto& q : faces)
            for (int i = 0; i < 4; ++i) {
                // A run of positive corners starts at q[i]; the segment runs from where it ends
                // (exit edge) back to where it starts (entry edge): positive side on the left.
                if (!positive(q[i]) || positive(q[(i + 3) % 4])) continue;
                int j = i;
                while (positive(q[(j + 1) % 4])) j = (j + 1) % 4;
                int entry = edge_index(table.edges, q[(i + 3) % 4], q[i]);
                int exit = edge_index(table.edges, q[j], q[(j + 1) % 4]);
                next[exit] = entry;
            }
        std::array<bool, 12> used{};
        for (int start = 0; start < 12; ++start) {
            if (next[start] < 0 || used[start]) continue;
            std::vector<int> loop;
            for (int e = start; !used[e]; e = next[e]) {
                used[e] = true;
                loop.push_back(e);
            }
            for (size_t k = 1; k + 1 < loop.size(); ++k)
                table.triangles[cube].push_back({uint8_t(loop[0]), uint8_t(loop[k]), uint8_t(loop[k + 1])});
        }
    }

    // Orientation: with only corner 0 inside the solid, the outward normal points to +(1,1,1).
    // Fix the winding once from this case (the construction is the same for every case).
    auto mid = [&](int e) {
        std::array<double, 3> p{};
        for (int a = 0; a < 3; ++a) p[a] = (table.edges[e].corner >> a) & 1;
        p[table.edges[e].axis] = 0.5;
        return p;
    };
    const auto& t = table.triangles[1].at(0);
    auto p0 = mid(t[0]), p1 = mid(t[1]), p2 = mid(t[2]);
    double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    double nx = e1[1] * e2[2] - e1[2] * e2[1], ny = e1[2] * e2[0] - e1[0] * e2[2], nz = e1[0] * e2[1] - e1[1] * e2[0];
    if (nx + ny + nz < 0)
        for (auto& tris : table.triangles)
            for (auto& tri : tris) std::swap(tri[1], tri[2]);
    return table;
}

// ---- The implicit solid ----------------------------------------------------------------------

// Solid where f > 0: min(gyroid(ω p) + bumps, ball). Every term is a sum of products of
// per-axis factors, so a grid plane is evaluated from per-axis tables without any sin/cos.
struct Shape {
    double omega, omega_bump, phase[3], bump_phase[3];
    static constexpr double kBump = 0.18, kRadius = 0.92, kBallScale = 4.0;

    explicit Shape(uint64_t seed) {
        Rng rng{seed ^ 0x5348415045ull};
        omega = 2 * std::numbers::pi * 2.0;  // 4 periods across [-1, 1]
        omega_bump = omega * 4.7;
        for (int a = 0; a < 3; ++a) {
            phase[a] = rng.uniform() * 2 * std::numbers::pi;
            bump_phase[a] = rng.uniform() * 2 * std::numbers::pi;
        }
    }
};

// Per-axis factors at grid coordinates x_i = -1 + 2i/n.
struct AxisTable {
    std::vector<float> x, s, c, bump, sq;
    AxisTable(const Shape& shape, int axis, int n) {
        for (int i = 0; i <= n; ++i) {
            double xi = -1.0 + 2.0 * i / n;
            x.push_back(float(xi));
            s.push_back(float(std::sin(shape.omega * xi + shape.phase[axis])));
            c.push_back(float(std::cos(shape.omega * xi + shape.phase[axis])));
            bump.push_back(float(std::sin(shape.omega_bump * xi + shape.bump_phase[axis])));
            sq.push_back(float(xi * xi));
        }
    }
};

// Evaluates plane k into `out` ((n+1)² values, x fastest).
void evaluate_plane(const AxisTable& X, const AxisTable& Y, const AxisTable& Z, int n, int k, std::vector<float>& out) {
    const float sz = Z.s[k], cz = Z.c[k], bz = float(Shape::kBump) * Z.bump[k], qz = Z.sq[k];
    const float r2 = float(Shape::kRadius * Shape::kRadius), ball = float(Shape::kBallScale);
    for (int j = 0; j <= n; ++j) {
        const float sy = Y.s[j], cy = Y.c[j], by = bz * Y.bump[j], qyz = r2 - Y.sq[j] - qz;
        float* row = &out[size_t(j) * (n + 1)];
        for (int i = 0; i <= n; ++i) {
            float g = X.s[i] * cy + sy * cz + sz * X.c[i] + by * X.bump[i];
            float b = ball * (qyz - X.sq[i]);
            row[i] = std::min(g, b);
        }
    }
}

struct Hole {
    float c[3];
    float r2;
    bool checker = false;  // keeps the cells whose i + j + k is even (--touching-holes)
};

// --hole-chains: cell (i, j, k) loses its triangles when i − j is a multiple of this and k is
// even. Cells (i, j, k) and (i + 1, j + 1, k) share the grid edge along z between them, whose
// surface vertex both holes' loops pass through; cells of one chain share no face, so the holes
// stay apart. 12 gives about 1 300 boundary edges at 17 000 triangles.
constexpr int kChainPeriod = 12;
bool on_chain(int i, int j, int k) { return (i - j) % kChainPeriod == 0 && (k & 1) == 0; }

std::vector<Hole> make_holes(uint64_t seed, int count, bool checker) {
    Rng rng{seed ^ 0x484f4c4553ull};
    std::vector<Hole> holes;
    for (int h = 0; h < count; ++h) {
        Hole hole;
        for (float& x : hole.c) x = float(rng.uniform() * 1.6 - 0.8);
        double r = 0.03 + 0.05 * rng.uniform();
        hole.r2 = float(r * r);
        hole.checker = checker;
        holes.push_back(hole);
    }
    return holes;
}

// Marches slabs [k_begin, k_end) of an n³ grid over [-1, 1]³ along z, passing each triangle
// (9 floats) to `emit`; returns the number of triangles emitted.
template <class Emit>
uint64_t march(const CaseTable& table, const Shape& shape, int n, const std::vector<Hole>& holes, bool chains,
               int k_begin, int k_end, Emit emit) {
    AxisTable X(shape, 0, n), Y(shape, 1, n), Z(shape, 2, n);
    const float h = 2.0f / float(n);
    const size_t stride = size_t(n) + 1;
    // Square codes: the 4 corner signs of grid square (i, j) of a plane, in the cube's bit
    // order, so a cell's case is lower | upper << 4. Rows are padded with zeros to a multiple
    // of 8 so empty runs are skipped 8 cells at a time.
    const size_t row = (size_t(n) + 7) / 8 * 8;
    std::vector<float> lower(stride * stride), upper(stride * stride);
    std::vector<uint8_t> lower_code(row * n + 8, 0), upper_code(row * n + 8, 0);
    auto square_codes = [&](const std::vector<float>& v, std::vector<uint8_t>& code) {
        for (int j = 0; j < n; ++j) {
            const float* r0 = &v[size_t(j) * stride];
            const float* r1 = r0 + stride;
            uint8_t* out = &code[size_t(j) * row];
            for (int i = 0; i < n; ++i)
                out[i] = uint8_t((r0[i] > 0) | (r0[i + 1] > 0) << 1 | (r1[i] > 0) << 2 | (r1[i + 1] > 0) << 3);
        }
    };
    evaluate_plane(X, Y, Z, n, k_begin, lower);
    square_codes(lower, lower_code);
    uint64_t count = 0;
    float tri[9];
    for (int k = k_begin; k < k_end; ++k) {
        evaluate_plane(X, Y, Z, n, k + 1, upper);
        square_codes(upper, upper_code);
        const float* plane[2] = {lower.data(), upper.data()};
        for (int j = 0; j < n; ++j) {
            const uint8_t* lo_row = &lower_code[size_t(j) * row];
            const uint8_t* hi_row = &upper_code[size_t(j) * row];
            for (int i = 0; i < n; ++i) {
                if ((i & 7) == 0) {
                    uint64_t lo8, hi8;
                    std::memcpy(&lo8, lo_row + i, 8);
                    std::memcpy(&hi8, hi_row + i, 8);
                    // All 8 cells outside, or all inside (padding cells are "outside", so a
                    // word with padding is never all inside).
                    if ((lo8 | hi8) == 0 || (lo8 & hi8) == 0x0F0F0F0F0F0F0F0Full) {
                        i += 7;
                        continue;
                    }
                }
                int cube = lo_row[i] | hi_row[i] << 4;
                if (cube == 0 || cube == 255) continue;
                // Corner c of this cell is at (i + bit0, j + bit1, k + bit2).
                auto value = [&](int c) {
                    return plane[(c >> 2) & 1][size_t(j + ((c >> 1) & 1)) * stride + size_t(i + (c & 1))];
                };
                float vertex[12][3];
                uint16_t have = 0;
                for (const auto& t : table.triangles[cube]) {
                    for (int v = 0; v < 3; ++v) {
                        int e = t[v];
                        if (!(have & (1u << e))) {
                            have |= uint16_t(1u << e);
                            const Edge& edge = table.edges[e];
                            int c0 = edge.corner, c1 = c0 | (1 << edge.axis);
                            float v0 = value(c0), v1 = value(c1);
                            float frac = v0 / (v0 - v1);
                            int gi = i + (c0 & 1), gj = j + ((c0 >> 1) & 1), gk = k + ((c0 >> 2) & 1);
                            float p[3] = {X.x[gi], Y.x[gj], Z.x[gk]};
                            p[edge.axis] += frac * h;
                            vertex[e][0] = p[0];
                            vertex[e][1] = p[1];
                            vertex[e][2] = p[2];
                        }
                        std::memcpy(&tri[3 * v], vertex[e], sizeof vertex[e]);
                    }
                    if (chains && on_chain(i, j, k)) continue;
                    if (!holes.empty()) {
                        float cx = (tri[0] + tri[3] + tri[6]) / 3, cy = (tri[1] + tri[4] + tri[7]) / 3,
                              cz = (tri[2] + tri[5] + tri[8]) / 3;
                        bool inside = false;
                        for (const Hole& hole : holes) {
                            float dx = cx - hole.c[0], dy = cy - hole.c[1], dz = cz - hole.c[2];
                            inside |= dx * dx + dy * dy + dz * dz < hole.r2 && (!hole.checker || ((i + j + k) & 1));
                        }
                        if (inside) continue;
                    }
                    ++count;
                    emit(tri);
                }
            }
        }
        lower.swap(upper);
        lower_code.swap(upper_code);
    }
    return count;
}

// Grid resolution for about `target` triangles: surface triangles grow like n², so scale from
// counting passes at lower resolutions (each at most ~2 M triangles, a fraction of a second).
int resolution_for(const CaseTable& table, const Shape& shape, const std::vector<Hole>& holes, bool chains,
                   uint64_t target) {
    constexpr double kCountCap = 4e5;
    auto count_at = [&](int n) {
        return double(std::max<uint64_t>(march(table, shape, n, holes, chains, 0, n, [](const float*) {}), 1));
    };
    int n = 48;
    double count = count_at(n);
    for (int round = 0; round < 3; ++round) {
        double estimate = n * std::sqrt(double(target) / count), reach = n * std::sqrt(kCountCap / count);
        int next = int(std::lround(std::min(estimate, reach)));
        if (next == n) break;
        n = next;
        count = count_at(n);
    }
    return std::max(2, int(std::lround(n * std::sqrt(double(target) / count))));
}

// Marches the whole grid with `threads` workers, each marching bands of a few slabs into a
// buffer, while the calling thread hands the bands to `emit` in slab order: the output is the
// same as a single-threaded march. Memory: at most 2 × threads bands of triangles.
template <class Emit>
uint64_t march_parallel(const CaseTable& table, const Shape& shape, int n, const std::vector<Hole>& holes, bool chains,
                        unsigned threads, Emit emit) {
    constexpr int kBandSlabs = 4;
    const int bands = (n + kBandSlabs - 1) / kBandSlabs;
    struct Slot {
        std::vector<float> xyz;
        bool ready = false;
    };
    std::vector<Slot> ring(2 * threads);
    std::mutex mutex;
    std::condition_variable changed;
    int next_claim = 0, next_emit = 0;
    auto worker = [&] {
        std::vector<float> local;
        for (;;) {
            int band;
            {
                std::unique_lock lock(mutex);
                band = next_claim++;
                if (band >= bands) return;
                changed.wait(lock, [&] { return band < next_emit + int(ring.size()); });
            }
            local.clear();
            int k0 = band * kBandSlabs, k1 = std::min(n, k0 + kBandSlabs);
            march(table, shape, n, holes, chains, k0, k1, [&](const float* tri) { local.insert(local.end(), tri, tri + 9); });
            std::lock_guard lock(mutex);
            Slot& slot = ring[size_t(band) % ring.size()];
            slot.xyz.swap(local);
            slot.ready = true;
            changed.notify_all();
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
    uint64_t count = 0;
    std::vector<float> batch;
    try {
        for (int band = 0; band < bands; ++band) {
            {
                std::unique_lock lock(mutex);
                Slot& slot = ring[size_t(band) % ring.size()];
                changed.wait(lock, [&] { return slot.ready; });
                batch.swap(slot.xyz);
                slot.ready = false;
                ++next_emit;
                changed.notify_all();
            }
            for (size_t t = 0; t < batch.size(); t += 9) emit(&batch[t]);
            count += batch.size() / 9;
        }
    } catch (...) {
        // Let the workers run out (they only compute), then rethrow.
        {
            std::lock_guard lock(mutex);
            next_claim = bands;
            next_emit = bands + int(ring.size());
            changed.notify_all();
        }
        for (auto& t : pool) t.join();
        throw;
    }
    for (auto& t : pool) t.join();
    return count;
}

struct GenOptions {
    std::string output, to;
    uint64_t triangles = 1'000'000;
    uint64_t seed = 1;
    bool shuffle = false, holes = false, touching_holes = false, hole_chains = false, quiet = false, color = false;
    unsigned threads = 0;  // 0: one per core
    std::string tmpdir;
};

// --color: the colour (RGB, 0..1, on the 8-bit grid) at a position of [-1, 1]³. Bands: a sine
// across x and y, about 3 periods over the solid; the border: the plane z = 0.2, warm above,
// cool below.
void colour_at(const float* p, float* rgba) {
    const double t = 0.5 + 0.5 * std::sin(9.0 * p[0] + 6.0 * p[1]);
    const bool warm = p[2] >= 0.2f;
    const double r = warm ? 0.95 : 0.10 + 0.25 * t, g = 0.20 + 0.60 * t, b = warm ? 0.10 + 0.25 * t : 0.95;
    for (const auto& [i, v] : {std::pair{0, r}, std::pair{1, g}, std::pair{2, b}})
        rgba[i] = float(std::round(v * 255) / 255);
    rgba[3] = 1;
}

int run(const GenOptions& opt) {
    auto start = std::chrono::steady_clock::now();
    CaseTable table = build_case_table();
    Shape shape(opt.seed);
    std::vector<Hole> holes;
    if (opt.holes || opt.touching_holes) holes = make_holes(opt.seed, 40, opt.touching_holes);
    int n = resolution_for(table, shape, holes, opt.hole_chains, opt.triangles);
    unsigned threads = opt.threads ? opt.threads : std::max(1u, std::thread::hardware_concurrency());

    io::WriteOptions wo;
    wo.tmpdir = opt.tmpdir;
    wo.comment = "meshstream-gen marching cubes";
    if (opt.color) wo.channels.color = io::ColorFormat{io::ScalarType::kUInt8, false};
    io::Output out = io::open_output(opt.output, opt.to, wo);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, wo.channels);
    // The chunk's last triangle, pushed: its corners' colours (--color).
    auto colour_last = [&] {
        if (!opt.color) return;
        const size_t i = chunk.size() - 1;
        for (int k = 0; k < 3; ++k) colour_at(&chunk.xyz()[9 * i + 3 * size_t(k)], chunk.color_at(i) + 4 * k);
    };
    auto flush = [&] {
        out.write(chunk);
        chunk.clear();
    };
    uint64_t count = 0;
    if (!opt.shuffle) {
        count = march_parallel(table, shape, n, holes, opt.hole_chains, threads, [&](const float* tri) {
            std::memcpy(chunk.push_slot(), tri, 9 * sizeof(float));
            colour_last();
            if (chunk.full()) flush();
        });
    } else {
        // Out-of-core shuffle: each triangle goes to a random bucket file; each bucket is then
        // shuffled in memory (Fisher–Yates) and written. Buckets hold ~128 MiB each.
        constexpr uint64_t kBucketBytes = uint64_t{128} << 20;
        size_t buckets = size_t(std::clamp<uint64_t>(opt.triangles * 36 / kBucketBytes + 1, 1, 64));
        std::vector<std::unique_ptr<io::TempFile>> files;
        for (size_t b = 0; b < buckets; ++b)
            files.push_back(std::make_unique<io::TempFile>(opt.tmpdir, "meshstream-gen"));
        Rng rng{opt.seed ^ 0x53485546ull};
        count = march_parallel(table, shape, n, holes, opt.hole_chains, threads,
                               [&](const float* tri) { files[rng.next() % buckets]->write(tri, 9 * sizeof(float)); });
        // One allocation for the largest bucket: growing the vector from bucket to bucket held
        // two buckets at once while it copied (251 MB for 10 M triangles, now 134).
        uint64_t largest = 0;
        for (const auto& file : files) largest = std::max(largest, file->size());
        std::vector<float> data(largest / sizeof(float));
        for (auto& file : files) {
            const size_t m = file->size() / (9 * sizeof(float));
            if (m > 0) file->read_at(0, data.data(), m * 9 * sizeof(float));
            for (size_t i = m; i > 1; --i) {
                size_t r = rng.next() % i;
                if (r != i - 1) std::swap_ranges(&data[9 * r], &data[9 * r + 9], &data[9 * (i - 1)]);
            }
            for (size_t i = 0; i < m; ++i) {
                std::memcpy(chunk.push_slot(), &data[9 * i], 9 * sizeof(float));
                colour_last();
                if (chunk.full()) flush();
            }
            file.reset();
        }
    }
    if (!chunk.empty()) flush();
    out.finish();
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!opt.quiet)
        std::fprintf(stderr, "meshstream-gen: %llu triangles (grid %d³%s%s%s%s) in %.2f s, %.2f M triangles/s -> %s\n",
                     (unsigned long long)count, n, opt.touching_holes ? ", touching holes" : opt.holes ? ", holes" : "",
                     opt.hole_chains ? ", hole chains" : "", opt.shuffle ? ", shuffled" : "",
                     opt.color ? ", coloured" : "", seconds, double(count) / seconds / 1e6, opt.output.c_str());
    return 0;
}

// The flags of meshstream-gen that set a library setting, as its errors name them; the
// library's words for the rest (it has no --memory: the default budget holds).
std::string gen_flag_name(io::Setting setting) {
    switch (setting) {
        case io::Setting::kOutput: return "OUTPUT";
        case io::Setting::kTo: return "--to";
        case io::Setting::kTmpdir: return "--tmpdir";
        case io::Setting::kSeed: return "--seed";
        case io::Setting::kThreads: return "--threads";
        default: return std::string(io::setting_words(setting));
    }
}

}  // namespace
}  // namespace meshstream::tools

int main(int argc, char** argv) {
    using namespace meshstream;
    tools::GenOptions opt;
    CLI::App app{
        "write a synthetic marching-cubes mesh, a triangle soup approximately sorted along z\n"
        "OUTPUT: a mesh file, its format from the extension (or --to), '-' for stdout with --to.\n"
        "A gyroid network with bumps, clipped to a ball, like a scanner pipeline's output. Memory: the bands\n"
        "of triangles in flight, about 45 MB for 10 M and 150 MB for 50 M triangles with two threads;\n"
        "--shuffle adds bucket files in --tmpdir and one bucket of at most 128 MiB in memory.",
        "meshstream-gen"};
    tools::use_help_formatter(app);
    app.add_option("OUTPUT", opt.output, "output mesh")->required();
    app.add_option("-n,--triangles", opt.triangles,
                   "about this many triangles (default 1000000)\n"
                   "Met within 1 % from about 10000 up; small counts overshoot: 100 gives 160")
        ->type_name("N")
        ->check(CLI::Range(uint64_t{100}, uint64_t{1} << 40));
    app.add_option("--seed", opt.seed, "random seed of the shape, holes and shuffle (default 1)")
        ->type_name("N")
        ->check(tools::whole_number(0, "a whole number"));
    app.add_flag("--shuffle", opt.shuffle, "write the triangles in random order (out of core)");
    app.add_flag("--holes", opt.holes, "punch 40 holes into the surface, like occlusions in a scan");
    app.add_flag("--touching-holes", opt.touching_holes,
                 "the holes of --holes keep every other grid cell: boundary loops that touch\n"
                 "at shared vertices, as hand-made and CAD-exported low-poly models have them");
    app.add_flag("--hole-chains", opt.hole_chains,
                 "one-cell holes in diagonal chains everywhere: loops touching at vertices");
    app.add_flag("--color", opt.color,
                 "an 8-bit RGB colour per corner from its position: smooth bands, a sharp border\n"
                 "For formats that hold vertex colours (PLY, OBJ, Draco, glTF)");
    app.add_option("--to", opt.to,
                   "output format, instead of the extension's (e.g. ply)\nOne of: " + io::format_names(true))
        ->type_name("FMT")
        ->check(CLI::Validator(
            [](const std::string& name) -> std::string {
                const io::Format* f = io::find_format(name);
                if (f != nullptr && f->open_writer != nullptr) return {};
                return "unknown output format '" + name + "' (one of: " + io::format_names(true) + ")";
            },
            ""));
    app.add_option("--tmpdir", opt.tmpdir, "where --shuffle's bucket files go (default: $TMPDIR or /tmp)")
        ->type_name("DIR");
    app.add_option("--threads", opt.threads, "marching threads (default: one per core; the output is the same)")
        ->type_name("N");
    app.add_flag("-q,--quiet", opt.quiet, "no summary line");
    app.set_version_flag("--version", std::string("meshstream-gen ") + MESHSTREAM_VERSION, "print the version");
    app.footer(
        "  meshstream-gen --triangles 10000000 big.stl\n"
        "  meshstream-gen -n 1000000 --shuffle --holes shuffled.ply");
    io::install_cleanup_handlers();
    if (const std::string unknown = tools::first_unknown_option(app, "", argc, argv); !unknown.empty()) {
        std::fprintf(stderr, "%s\n",
                     tools::usage_error_line("meshstream-gen", "", "unknown option " + unknown).c_str());
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --help-all, --version
        std::fprintf(stderr, "%s\n", tools::parse_error_line(app, e, "meshstream-gen", "").c_str());
        return 2;
    }
    // An output whose format cannot be told is a bad command line, as in meshstream.
    if (opt.to.empty() && io::format_for_extension(opt.output, true) == nullptr) {
        const std::string name = opt.output == "-" ? "<stdout>" : opt.output;
        std::fprintf(stderr, "meshstream-gen: %s: cannot tell the output format from the name (use --to, one of: %s)\n",
                     name.c_str(), io::format_names(true).c_str());
        return 2;
    }
    if (opt.color) {
        const io::Format* format =
            opt.to.empty() ? io::format_for_extension(opt.output, true) : io::find_format(opt.to);
        io::Channels coloured;
        coloured.color = io::ColorFormat{};
        if (!io::writable_channels(*format, coloured, {}).color) {
            std::fprintf(stderr,
                         "meshstream-gen: %s: --color: %s holds no vertex colours (PLY, OBJ, Draco and glTF do)\n",
                         opt.output == "-" ? "<stdout>" : opt.output.c_str(), std::string(format->name).c_str());
            return 2;
        }
    }
    try {
        return tools::run(opt);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "meshstream-gen: error: out of memory\n");
        return 1;
    } catch (const meshstream::Error& e) {
        std::fprintf(stderr, "meshstream-gen: error: %s\n", e.describe(tools::gen_flag_name).c_str());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "meshstream-gen: error: %s\n", e.what());
        return 1;
    }
}
