// 3D Tiles out of core: see tiles.hpp for the method, docs/tiles.md for the format's details.
#include "engine/tiles.hpp"

#include "compare/metro.hpp"
#include "engine/convert.hpp"
#include "engine/decimate.hpp"
#include "engine/files.hpp"
#include "engine/units.hpp"
#include "io/gltf.hpp"
#include "io/pipeline.hpp"
#include "io/triangle_input.hpp"
#include "sort/external_sort.hpp"
#include "sort/radix.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <set>
#include <limits>
#include <thread>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <numbers>
#include <filesystem>
#include <fstream>
#include <list>
#include <map>
#include <memory>
#include <unordered_map>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace meshstream::engine {

namespace {

namespace fs = std::filesystem;
using io::mention;
using io::Setting;
using Json = nlohmann::json;

constexpr int kMaxDepth = 10;  // cell keys: 3 bits a depth, 30 bits
constexpr uint64_t kMinTileTriangles = 256;
// Depths a tileset file holds: at most 1 + 8 + 64 tiles and 512 references to files below
// (about 200 kB of JSON).
constexpr int kDepthsPerFile = 3;

// The bounding cube and the cell key of a point: the Morton code of its depth-10 cell.
struct Cube {
    double origin[3] = {0, 0, 0};
    double extent = 1;

    uint32_t key(const float* p) const {
        uint32_t cell[3];
        for (int a = 0; a < 3; ++a) {
            const double t = (double(p[a]) - origin[a]) * (double(1 << kMaxDepth) / extent);
            cell[a] = t <= 0 || !std::isfinite(t) ? 0 : uint32_t(std::min(t, double((1 << kMaxDepth) - 1)));
        }
        static_assert(kMaxDepth == 10, "sort::morton30 interleaves 10 bits");
        return sort::morton30(cell[0], cell[1], cell[2]);
    }
    uint32_t triangle_key(const float* xyz) const {
        const float c[3] = {(xyz[0] + xyz[3] + xyz[6]) / 3, (xyz[1] + xyz[4] + xyz[7]) / 3,
                            (xyz[2] + xyz[5] + xyz[8]) / 3};
        return key(c);
    }
};

// The octant of depth `depth` (1-based) in a key.
int octant(uint32_t key, int depth) { return int(key >> (3 * (kMaxDepth - depth))) & 7; }

// An axis-aligned box in the model's coordinates (empty: min > max).
struct Box {
    double min[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, max[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    bool empty() const { return min[0] > max[0]; }
    void add(const float* p) {
        for (int a = 0; a < 3; ++a) min[a] = std::min(min[a], double(p[a])), max[a] = std::max(max[a], double(p[a]));
    }
    void add(const Box& b) {
        for (int a = 0; a < 3; ++a) min[a] = std::min(min[a], b.min[a]), max[a] = std::max(max[a], b.max[a]);
    }
    bool meets(const Box& b) const {
        for (int a = 0; a < 3; ++a)
            if (min[a] > b.max[a] || max[a] < b.min[a]) return false;
        return true;
    }
    double diagonal() const {
        if (empty()) return 0;
        double d = 0;
        for (int a = 0; a < 3; ++a) d += (max[a] - min[a]) * (max[a] - min[a]);
        return std::sqrt(d);
    }
};

// Triangles per cell key (a centroid's depth-10 cell): an open-addressing table (linear
// probing, load at most 1/2) of the cells met, 12 bytes a slot. A mesh meets about one cell a
// triangle up to a few million triangles; past `budget_bytes` (the table and, while it grows,
// the one before it) the counts go to cells of the depth above, 8 times as large, as often as
// needed, and keys count at that depth (their lower bits 0): depth() says which.
class CellCounts {
public:
    explicit CellCounts(uint64_t budget_bytes)
        : max_slots_(std::max<uint64_t>(kFirstSlots, budget_bytes / (3 * kSlotBytes))) {}

    void add(uint32_t key) {
        size_t i = slot(key & mask_);
        if (keys_[i] == kEmpty) {
            keys_[i] = key & mask_;
            if (2 * ++size_ > keys_.size()) {
                if (2 * keys_.size() <= max_slots_)
                    rehash(2 * keys_.size());
                else
                    while (2 * size_ > keys_.size()) coarsen();
                i = slot(key & mask_);
            }
        }
        ++counts_[i];
    }
    bool empty() const { return size_ == 0; }
    int depth() const { return depth_; }
    // (key, count) of every cell met, by key.
    std::vector<std::pair<uint32_t, uint64_t>> sorted() const {
        std::vector<std::pair<uint32_t, uint64_t>> out;
        out.reserve(size_);
        for (size_t i = 0; i < keys_.size(); ++i)
            if (keys_[i] != kEmpty) out.emplace_back(keys_[i], counts_[i]);
        std::sort(out.begin(), out.end());
        return out;
    }

private:
    static constexpr uint32_t kEmpty = ~uint32_t{0};  // keys have 30 bits
    static constexpr uint64_t kSlotBytes = sizeof(uint32_t) + sizeof(uint64_t);
    static constexpr size_t kFirstSlots = 1024;
    size_t slot(uint32_t key) const {
        const size_t mask = keys_.size() - 1;
        size_t i = (uint64_t{key} * 0x9E3779B97F4A7C15ull >> 32) & mask;
        while (keys_[i] != kEmpty && keys_[i] != key) i = (i + 1) & mask;
        return i;
    }
    // The table made anew with `slots` slots, the keys under the current mask.
    void rehash(size_t slots) {
        std::vector<uint32_t> keys(slots, kEmpty);
        std::vector<uint64_t> counts(slots, 0);
        std::swap(keys, keys_), std::swap(counts, counts_);
        size_ = 0;
        for (size_t i = 0; i < keys.size(); ++i)
            if (keys[i] != kEmpty) {
                const size_t j = slot(keys[i] & mask_);
                size_ += keys_[j] == kEmpty;
                keys_[j] = keys[i] & mask_, counts_[j] += counts[i];
            }
    }
    void coarsen() {
        --depth_;
        mask_ <<= 3;
        rehash(keys_.size());
    }
    uint64_t max_slots_;
    uint32_t mask_ = ~uint32_t{0};
    int depth_ = kMaxDepth;
    std::vector<uint32_t> keys_ = std::vector<uint32_t>(kFirstSlots, kEmpty);
    std::vector<uint64_t> counts_ = std::vector<uint64_t>(kFirstSlots, 0);
    size_t size_ = 0;
};

struct Node {
    uint32_t prefix = 0;  // the key's bits above this depth (the rest 0)
    int depth = 0;
    uint64_t count = 0;  // input triangles with their centroid here
    bool leaf = true;
    std::array<int, 8> child{-1, -1, -1, -1, -1, -1, -1, -1};
    // Filled as the tiles are written.
    Box box;  // the content's
    uint64_t triangles = 0, bytes = 0;
    double error = 0;
    std::string uri;  // relative to the tileset; empty: no content
};

struct Tree {
    std::vector<Node> nodes;  // nodes[0] the root
    int max_depth = 0;

    // Builds the cells of [lo, hi) of the sorted (key, count) list under `prefix` at `depth`.
    // Cells split down to `deepest` (the depth the counts are of) at most.
    int build(const std::vector<std::pair<uint32_t, uint64_t>>& cells, size_t lo, size_t hi, uint32_t prefix,
              int depth, uint64_t budget, int deepest) {
        const int id = int(nodes.size());
        nodes.emplace_back();
        uint64_t count = 0;
        for (size_t i = lo; i < hi; ++i) count += cells[i].second;
        nodes[id].prefix = prefix;
        nodes[id].depth = depth;
        nodes[id].count = count;
        max_depth = std::max(max_depth, depth);
        if (count <= budget || depth >= deepest) return id;
        nodes[id].leaf = false;
        size_t i = lo;
        for (int o = 0; o < 8; ++o) {
            size_t j = i;
            while (j < hi && octant(cells[j].first, depth + 1) == o) ++j;
            if (j > i) {
                const int c = build(cells, i, j, prefix | uint32_t(o) << (3 * (kMaxDepth - depth - 1)), depth + 1, budget,
                                    deepest);
                nodes[id].child[o] = c;
            }
            i = j;
        }
        return id;
    }

    // The node a key falls in at `depth`, or the leaf above it; -1 when no cell holds it.
    int at(uint32_t key, int depth) const {
        int n = 0;
        while (!nodes[n].leaf && nodes[n].depth < depth) {
            n = nodes[n].child[octant(key, nodes[n].depth + 1)];
            if (n < 0) return -1;
        }
        return n;
    }
};

// Gives the heap's free memory back to the system; called between the steps. Each step frees
// its buffers at its end (the sort's runs, a level's decimators, the errors' indexes on threads
// of their own), but glibc keeps freed memory below its heap's top and in each thread's arena,
// where it would stay resident under the next step's peak.
void release_free_memory() {
#ifdef __GLIBC__
    malloc_trim(0);
#endif
}

// A directory removed with everything in it unless kept.
class DirectoryGuard {
public:
    explicit DirectoryGuard(std::string path) : path_(std::move(path)) {}
    ~DirectoryGuard() {
        if (!path_.empty()) {
            std::error_code ec;
            fs::remove_all(path_, ec);
        }
    }
    DirectoryGuard(const DirectoryGuard&) = delete;
    DirectoryGuard& operator=(const DirectoryGuard&) = delete;
    const std::string& path() const { return path_; }
    void keep() { path_.clear(); }

private:
    std::string path_;
};

std::string make_directory_beside(const std::string& target, const std::string& tag) {
    std::string pattern = target + "." + tag + "-XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr)
        throw io::Error(target, "cannot create a directory beside it: " + std::string(std::strerror(errno)));
    return pattern;
}

// The forwarding sink of a step: its phases labelled "tiles: <step>: <phase>".
class StepProgress final : public ProgressSink {
public:
    StepProgress(ProgressSink& out, std::string step) : out_(out), step_(std::move(step)) {}
    void phase(std::string label, std::optional<uint64_t> total) override {
        out_.phase("tiles: " + step_ + ": " + label, total);
    }
    void update(uint64_t done) override { out_.update(done); }
    void update(uint64_t done, uint64_t bytes_read, std::optional<uint64_t> file_bytes) override {
        out_.update(done, bytes_read, file_bytes);
    }
    void status(const std::string& text) override { out_.status("tiles: " + step_ + ": " + text); }
    bool cancelled() const override { return out_.cancelled(); }

private:
    ProgressSink& out_;
    std::string step_;
};

io::GltfSettings::Compression gltf_compression(TileCompression c) {
    switch (c) {
        case TileCompression::kDraco: return io::GltfSettings::Compression::kDraco;
        case TileCompression::kNone: return io::GltfSettings::Compression::kNone;
        case TileCompression::kMeshopt: break;
    }
    return io::GltfSettings::Compression::kMeshopt;
}

// The column-major 4 × 4 transform from east-north-up at `o` to Earth-centred, Earth-fixed
// coordinates (WGS84).
std::array<double, 16> enu_to_ecef(const GeoOrigin& o) {
    constexpr double kA = 6378137.0, kF = 1 / 298.257223563;
    constexpr double kE2 = kF * (2 - kF);
    const double lon = o.longitude * std::numbers::pi / 180, lat = o.latitude * std::numbers::pi / 180;
    const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
    const double n = kA / std::sqrt(1 - kE2 * sl * sl);
    const double x = (n + o.height) * cl * co, y = (n + o.height) * cl * so, z = (n * (1 - kE2) + o.height) * sl;
    return {-so, co, 0, 0,                 // east
            -sl * co, -sl * so, cl, 0,     // north
            cl * co, cl * so, sl, 0,       // up
            x, y, z, 1};
}

// A tile's triangles, turned y-up, on their way to its GLB.
struct TileJob {
    int node = -1;
    std::vector<io::TriangleChunk> chunks;
};

// Runs `write` on the jobs given, on `threads` threads (each job on one; with one thread, on
// the caller's at once). At most 2 × threads jobs wait, so memory holds about 3 × threads tiles.
class TilePool {
public:
    TilePool(unsigned threads, std::function<void(TileJob&)> write) : write_(std::move(write)) {
        if (threads <= 1) return;
        for (unsigned t = 0; t < threads; ++t) workers_.emplace_back([this] { work(); });
        capacity_ = 2 * size_t(threads);
    }
    // Without finish() (an error or a cancel): the jobs still waiting are dropped.
    ~TilePool() {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            queue_.clear();
        }
        stop();
    }
    TilePool(const TilePool&) = delete;
    TilePool& operator=(const TilePool&) = delete;

    // Writes `job`, or queues it once there is room; rethrows a failed job's error.
    void submit(TileJob job) {
        if (workers_.empty()) {
            write_(job);
            return;
        }
        std::unique_lock<std::mutex> lock(mutex_);
        room_.wait(lock, [&] { return queue_.size() < capacity_ || failure_; });
        if (failure_) std::rethrow_exception(failure_);
        queue_.push_back(std::move(job));
        ready_.notify_one();
    }
    // Waits for every job; rethrows a failed job's error.
    void finish() {
        stop();
        if (failure_) std::rethrow_exception(failure_);
    }

private:
    void work() {
        for (;;) {
            TileJob job;
            {
                std::unique_lock<std::mutex> lock(mutex_);
                ready_.wait(lock, [&] { return !queue_.empty() || done_; });
                if (queue_.empty() || failure_) return;
                job = std::move(queue_.front());
                queue_.pop_front();
                room_.notify_one();
            }
            try {
                write_(job);
            } catch (...) {
                const std::lock_guard<std::mutex> lock(mutex_);
                if (!failure_) failure_ = std::current_exception();
                room_.notify_all();
                return;
            }
        }
    }
    // Lets the workers empty the queue (none left after a failure) and joins them.
    void stop() {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            done_ = true;
        }
        ready_.notify_all();
        for (std::thread& w : workers_) w.join();
        workers_.clear();
    }

    std::function<void(TileJob&)> write_;
    std::vector<std::thread> workers_;
    size_t capacity_ = 0;
    std::deque<TileJob> queue_;
    std::mutex mutex_;
    std::condition_variable ready_, room_;
    bool done_ = false;
    std::exception_ptr failure_;
};

// Positions (y-up) as a tile's GLB stores them on `grid`: each coordinate the nearest of the
// grid's 2^bits values over its extent, clamped to it, as meshopt's and Draco's quantizers
// place it (to within a float's rounding of the decoder's arithmetic).
void snap_to_grid(std::vector<float>& xyz, const io::GltfSettings::Grid& grid) {
    const double steps = double((uint64_t{1} << grid.bits) - 1), step = double(grid.extent) / steps;
    for (size_t i = 0; i < xyz.size(); ++i) {
        const double origin = grid.origin[i % 3];
        const double q = std::clamp(std::nearbyint((double(xyz[i]) - origin) / step), 0.0, steps);  // NaN stays
        xyz[i] = float(origin + q * step);
    }
}

// Every tile's positions as a viewer gets them (on the quantization grid, as its GLB stores
// them; what a writer leaves out, Draco's degenerate triangles, has no area), in one temporary
// file, for the error measure: a tile is needed again each time a tile near it is measured,
// and then costs a read of its bytes (from the page cache, mostly), not a decode.
// Disk: 36 bytes a triangle of every tile (the levels above the leaves add at most a third)
// and 3.5 kB a tile.
class TileStore {
public:
    explicit TileStore(const std::string& dir) : file_(dir, "tile-positions") {}

    // Stores tile `node`'s positions (y-up, 9 floats a triangle). Thread-safe.
    void add(int node, const std::vector<float>& xyz) {
        // The triangles by their centroid's cell of a 4 × 4 × 4 grid over the tile's box, each
        // cell's run with its content's box, so that a crop reads the runs that meet it.
        const size_t n = xyz.size() / 9;
        Box box;
        for (size_t i = 0; i < xyz.size(); i += 3) box.add(&xyz[i]);
        std::vector<uint8_t> cell(n);
        std::array<Run, kCells> runs{};
        for (size_t t = 0; t < n; ++t) {
            int c = 0;
            for (int a = 0; a < 3; ++a) {
                const double centre = (double(xyz[9 * t + a]) + xyz[9 * t + 3 + a] + xyz[9 * t + 6 + a]) / 3;
                const double f = (centre - box.min[a]) / (box.max[a] - box.min[a]) * kSide;
                c = c * kSide + (f > 0 ? int(std::min(f, double(kSide - 1))) : 0);  // NaN (a flat box): 0
            }
            cell[t] = uint8_t(c);
            ++runs[size_t(c)].count;
        }
        uint32_t first = 0;
        for (Run& r : runs) r.first = first, first += r.count;
        std::vector<float> sorted(xyz.size());
        std::array<uint32_t, kCells> at{};
        for (size_t c = 0; c < kCells; ++c) at[c] = runs[c].first;
        for (size_t t = 0; t < n; ++t) {
            const uint32_t to = at[cell[t]]++;
            std::copy_n(&xyz[9 * t], 9, &sorted[9 * size_t(to)]);
            Box b;
            for (int k = 0; k < 3; ++k) b.add(&xyz[9 * t + 3 * size_t(k)]);
            runs[cell[t]].box.add(b);
        }
        const std::lock_guard<std::mutex> lock(mutex_);
        at_[node] = {file_.size(), sorted.size()};
        file_.write(sorted.data(), sorted.size() * sizeof(float));
        file_.write(runs.data(), sizeof runs);
    }
    // Makes what add() wrote readable by get(); call once the tiles of a depth are written.
    void flush() {
        const std::lock_guard<std::mutex> lock(mutex_);
        file_.flush();
    }
    // Tile `node`'s positions (y-up), 9 floats a triangle. Thread-safe while nothing is added.
    std::vector<float> get(int node) const {
        const auto [offset, floats] = at_.at(node);
        std::vector<float> xyz(floats);
        file_.read_flushed_at(offset, xyz.data(), floats * sizeof(float));
        return xyz;
    }
    // Appends to `out` the triangles of tile `node` whose bounding box meets `crop` (y-up),
    // reading only the runs whose box meets it. Thread-safe while nothing is added.
    void append_within(int node, const Box& crop, std::vector<float>& out) const {
        const auto [offset, floats] = at_.at(node);
        std::array<Run, kCells> runs;
        file_.read_flushed_at(offset + floats * sizeof(float), runs.data(), sizeof runs);
        thread_local std::vector<float> buffer;
        for (const Run& r : runs) {
            if (r.count == 0 || !r.box.meets(crop)) continue;
            buffer.resize(9 * size_t(r.count));
            file_.read_flushed_at(offset + 9 * sizeof(float) * uint64_t(r.first), buffer.data(),
                                  buffer.size() * sizeof(float));
            for (size_t t = 0; t < buffer.size(); t += 9) {
                Box b;
                for (int c = 0; c < 3; ++c) b.add(&buffer[t + 3 * size_t(c)]);
                if (b.meets(crop)) out.insert(out.end(), &buffer[t], &buffer[t] + 9);
            }
        }
    }

private:
    static constexpr int kSide = 4;
    static constexpr size_t kCells = kSide * kSide * kSide;
    struct Run {  // a grid cell's triangles in the file, after the tile's
        uint32_t first = 0, count = 0;
        Box box;
    };
    io::TempFile file_;
    std::mutex mutex_;
    std::unordered_map<int, std::pair<uint64_t, size_t>> at_;  // node: byte offset, floats
};

// One level's tiles from a mesh file: its triangles sorted by cell key (sort()), then each run
// of a tile's cell written as that tile's GLB (write()), on s.threads threads.
class TileWriter {
public:
    // Builds in `root`; notes name the tiles under `shown_root`, where they will be.
    // Each tile's positions go to `store` too, as read back.
    TileWriter(const TilesSettings& s, Tree& tree, const Cube& cube, const std::string& root, std::string shown_root,
               TileStore& store)
        : s_(s), tree_(tree), cube_(cube), root_(root), shown_root_(std::move(shown_root)), store_(store) {}

    // Reads `mesh` into the sorter by cell key, counting the keys in `counts` when given.
    // Notes what the reader dropped or changed in `warnings` and the input's name and count in
    // `result`, when given. Returns the box of the triangles sorted.
    io::Bounds sort(const std::string& mesh, std::string_view format, CellCounts* counts, ProgressSink& progress,
                    Warnings* warnings, TilesResult* result, uint64_t vertex_table_bytes = 0) {
        // The reader's share of the memory budget (what a PLY or OBJ reader holds: its vertex
        // table, spilled past it): 3/16, beside the sort's 3/8 and the cell counts' 3/16; the
        // last quarter for the rest (chunks, the tiles being written). A vertex table (of
        // `vertex_table_bytes`) that fits in 3/8 is given whole, out of the sort's share: past
        // its share a table is read a page for each corner it lacks, which costs far more than
        // the sort's merging more runs.
        const uint64_t budget = s_.read.memory_budget_bytes;
        uint64_t reader_bytes = budget * 3 / 16, sort_bytes = budget * 3 / 8;
        if (vertex_table_bytes > reader_bytes && vertex_table_bytes + (64 << 10) <= budget * 3 / 8) {
            reader_bytes = vertex_table_bytes + (64 << 10);
            sort_bytes = budget * 9 / 16 - reader_bytes;
        }
        io::ReadOptions read = s_.read;
        read.memory_budget_bytes = reader_bytes;
        io::TriangleInput in(io::open_input(mesh, format, read), io::BadTriangles::kDrop);
        const io::MeshHeader& header = in.header();
        const io::Format& glb = io::output_format("x.glb", "glb");
        wo_ = io::WriteOptions{};
        wo_.tmpdir = s_.read.tmpdir;
        wo_.memory_budget_bytes = s_.read.memory_budget_bytes;
        io::GltfSettings gs(gltf_compression(s_.compression));
        gs.grid = grid_;  // the levels' tiles on the leaves' grid
        wo_.format_options.set(gs);
        const io::Channels wanted = s_.read.channels.of(header.channels);
        wo_.channels = io::writable_channels(glb, wanted, wo_);
        wo_.channels.vertex_id = false;
        if (warnings != nullptr) {
            if (const std::string dropped = io::describe_missing(wanted, wo_.channels); !dropped.empty())
                warnings->note("channels_dropped", dropped_channels_text(dropped, glb, wo_.channels));
        }

        sort::SorterOptions so;
        so.memory_budget_bytes = sort_bytes;
        so.tmpdir = s_.read.tmpdir;
        so.channels = wo_.channels;
        so.key = [this](const float* xyz) { return cube_.triangle_key(xyz); };
        sorter_.emplace(so);
        io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, wo_.channels);
        progress.phase("sorting by cell", header.triangle_count);
        // With threads, the input is read on a thread of its own; this thread sorts (and counts).
        const std::optional<uint64_t> file_bytes = in.source().stored_size();
        std::vector<uint32_t> keys;  // a chunk's, for the sorter and the counts
        io::Bounds box;
        box.min.fill(std::numeric_limits<float>::infinity());
        box.max.fill(-std::numeric_limits<float>::infinity());
        auto add = [&](uint64_t read_so_far, uint64_t offset) {
            keys.resize(chunk.size());
            const float* xyz = chunk.xyz().data();
            for (size_t i = 0; i < chunk.size(); ++i) keys[i] = cube_.triangle_key(xyz + 9 * i);
            // (The policy dropped the triangles with a NaN or infinite coordinate.)
            for (size_t i = 0; i < 9 * chunk.size(); i += 3)
                for (int a = 0; a < 3; ++a) {
                    box.min[a] = std::min(box.min[a], xyz[i + a]);
                    box.max[a] = std::max(box.max[a], xyz[i + a]);
                }
            sorter_->add(chunk, keys);
            if (counts != nullptr)
                for (const uint32_t key : keys) counts->add(key);
            progress.update(read_so_far, offset, file_bytes);
            throw_if_cancelled(progress);
        };
        if (s_.threads < 2) {
            while (in.next(chunk)) add(in.count().read, in.source().stored_offset());
        } else if (io::IndexedReadAhead::possible(in, wo_.channels)) {
            // A PLY: its corners looked up on two threads (the lookups are most of its reading).
            io::IndexedReadAhead reader(in, chunk.capacity(), wo_.channels, wanted);
            while (reader.next(chunk)) add(reader.count().read, reader.stored_offset());
        } else {
            io::ReadAhead reader(in, chunk.capacity(), wo_.channels);
            while (reader.next(chunk)) add(reader.count().read, reader.stored_offset());
        }
        sorter_->finish_input();
        // The material table is whole once the input is read.
        if (wo_.channels.material) wo_.materials = in.header().materials;
        if (warnings != nullptr) {
            note_dropped_triangles(dropped_triangles(in), "left out", *warnings);
            note_input_changes(in.header(), in.name(), *warnings);
        }
        if (result != nullptr) {
            result->input_name = in.name();
            result->input_format = std::string(in.format().name);
            result->triangles_in = in.count().read;
        }
        return box;
    }

    // Quantizes every tile's positions on one grid over the cube, so that a position two tiles
    // share decodes to the same float in both: meshopt's 16 bits (the most KHR_mesh_quantization
    // holds); Draco's 14 bits over the deepest leaves' cells (its default over a mesh's own box),
    // so 14 + `deepest` over the cube, at most 24 (a float's precision) and fewer while the
    // writers' coding tables (4 bytes a step, one set a thread) would pass an eighth of the
    // memory budget. Returns the step.
    double set_grid(int deepest) {
        io::GltfSettings gs = wo_.format_options.get<io::GltfSettings>();
        if (gs.compression == io::GltfSettings::Compression::kNone) return 0;
        io::GltfSettings::Grid grid;
        // The cube turned y-up, as the positions are: (x, z, -y).
        grid.origin[0] = float(cube_.origin[0]);
        grid.origin[1] = float(cube_.origin[2]);
        grid.origin[2] = float(-(cube_.origin[1] + cube_.extent));
        grid.extent = float(cube_.extent);
        grid.bits = 16;
        if (gs.compression == io::GltfSettings::Compression::kDraco) {
            grid.bits = std::min(14 + deepest, 24);
            const uint64_t tables = s_.read.memory_budget_bytes / 8 / uint64_t(std::max(s_.threads, 1u));
            while (grid.bits > 14 && (uint64_t{4} << grid.bits) > tables) --grid.bits;
        }
        gs.grid = grid_ = grid;
        wo_.format_options.set(gs);
        return cube_.extent / double((uint64_t{1} << grid.bits) - 1);
    }

    // Writes the tiles of the sorted triangles whose cell `select` picks (a node id, or -1 to
    // skip the triangle); counts in `region[d]` the triangles whose node at depth d is not a
    // leaf. With `copy`, writes every sorted triangle there too, as a triangle stream.
    void write(const std::function<int(uint32_t)>& select, std::vector<uint64_t>* region, ProgressSink& progress,
               const std::string& copy = {}) {
        std::optional<io::Output> copied;
        if (!copy.empty()) {
            io::WriteOptions co;
            co.tmpdir = s_.read.tmpdir;
            co.memory_budget_bytes = s_.read.memory_budget_bytes;
            co.channels = wo_.channels;
            co.materials = wo_.materials;
            co.triangle_count = sorter_->triangle_count();  // in its header: read without a count
            copied.emplace(io::open_output(copy, "stream", co));
        }
        std::vector<std::vector<std::string>> notes(tree_.nodes.size());
        std::vector<int> written;  // the tiles in the order written
        TilePool pool(s_.threads, [&](TileJob& job) { write_tile(job, notes[size_t(job.node)]); });

        progress.phase("writing tiles", sorter_->triangle_count());
        io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, wo_.channels);
        TileJob job;
        uint64_t done = 0;
        auto close = [&] {
            if (job.node < 0) return;
            pool.submit(std::move(job));
            job = TileJob{};
        };
        while (sorter_->next(chunk)) {
            if (copied) copied->write(chunk);
            for (size_t i = 0; i < chunk.size(); ++i) {
                const float* xyz = &chunk.xyz()[9 * i];
                const uint32_t key = cube_.triangle_key(xyz);
                if (region != nullptr)
                    for (int n = 0; n >= 0 && !tree_.nodes[size_t(n)].leaf;) {
                        const Node& node = tree_.nodes[size_t(n)];
                        if (size_t(node.depth) < region->size()) ++(*region)[size_t(node.depth)];
                        n = node.child[octant(key, node.depth + 1)];
                    }
                const int target = select(key);
                if (target < 0) continue;
                if (target != job.node) {
                    close();
                    job.node = target;
                    written.push_back(target);
                    Node& n = tree_.nodes[size_t(target)];
                    n.uri = "tiles/" + std::to_string(n.depth) + "/" +
                            std::to_string(n.prefix >> (3 * (kMaxDepth - n.depth))) + ".glb";
                    fs::create_directories(fs::path(root_) / "tiles" / std::to_string(n.depth));
                }
                Node& n = tree_.nodes[size_t(target)];
                for (int c = 0; c < 3; ++c) n.box.add(xyz + 3 * c);
                ++n.triangles;
                if (job.chunks.empty() || job.chunks.back().full())
                    job.chunks.emplace_back(io::TriangleChunk::kDefaultCapacity, wo_.channels);
                io::TriangleChunk& out = job.chunks.back();
                // y-up for glTF: (x, y, z) → (x, z, -y).
                out.push_copy(chunk, i);
                float* p = &out.xyz()[9 * (out.size() - 1)];
                for (int c = 0; c < 3; ++c) {
                    const float y = p[3 * c + 1];
                    p[3 * c + 1] = p[3 * c + 2];
                    p[3 * c + 2] = -y;
                }
                if (float* nrm = out.normal_at(out.size() - 1))
                    for (int c = 0; c < 3; ++c) {
                        const float y = nrm[3 * c + 1];
                        nrm[3 * c + 1] = nrm[3 * c + 2];
                        nrm[3 * c + 2] = -y;
                    }
            }
            done += chunk.size();
            progress.update(done);
            throw_if_cancelled(progress);
        }
        close();
        pool.finish();
        if (copied) copied->finish();
        // What the writer could not keep (Draco's degenerate triangles, images of other types)
        // is said, the first tiles' notes whole, in the order the tiles were written.
        for (int id : written) {
            if (notes[size_t(id)].empty()) continue;
            if (++tiles_with_notes_ > kNotedTiles) continue;
            for (std::string note : notes[size_t(id)]) {
                for (size_t at; (at = note.find(root_)) != std::string::npos;) note.replace(at, root_.size(), shown_root_);
                notes_.note("output_note", note);
            }
        }
        sorter_.reset();
    }

    // The writers' notes, into `warnings`.
    void report_notes(Warnings& warnings) const {
        warnings.merge(notes_);
        if (tiles_with_notes_ > kNotedTiles)
            warnings.note("output_note", std::to_string(tiles_with_notes_ - kNotedTiles) +
                                             " more tiles have notes like these from the glTF writer");
    }

private:
    // A tile's GLB: its triangles and, for the notes, what its writer said.
    void write_tile(TileJob& job, std::vector<std::string>& notes) const {
        Node& n = tree_.nodes[size_t(job.node)];
        io::WriteOptions wo = wo_;
        // A leaf holds its input triangles; a tile above, a decimation of them (not known before).
        wo.expected_triangle_count = n.leaf && n.count ? n.count : std::optional<uint64_t>();
        io::Output tile = io::open_output((fs::path(root_) / n.uri).string(), "glb", wo);
        std::vector<float> drawn;  // the positions, for the errors
        size_t triangles = 0;
        for (const io::TriangleChunk& c : job.chunks) triangles += c.size();
        drawn.reserve(9 * triangles);
        for (const io::TriangleChunk& c : job.chunks) {
            tile.write(c);
            drawn.insert(drawn.end(), c.xyz().begin(), c.xyz().end());
        }
        job.chunks.clear();
        if (wo.channels.material) tile.writer->update_materials(wo.materials);
        tile.finish();
        notes = tile.writer->raw_notes();
        n.bytes = fs::file_size(fs::path(root_) / n.uri);
        if (grid_) snap_to_grid(drawn, *grid_);
        store_.add(job.node, drawn);
    }

    static constexpr uint64_t kNotedTiles = 5;
    Warnings notes_;
    uint64_t tiles_with_notes_ = 0;
    const TilesSettings& s_;
    Tree& tree_;
    const Cube& cube_;
    std::string root_;
    std::string shown_root_;
    TileStore& store_;
    std::optional<sort::ExternalSorter> sorter_;
    io::WriteOptions wo_;
    std::optional<io::GltfSettings::Grid> grid_;  // set_grid's, for every level
};

// The geometric error of a tile: the Hausdorff distance between what a viewer draws with it
// and what it draws with its children instead, plus their largest error (0 without content:
// nothing is drawn instead of the children). Triangles go to tiles by centroid, so near a
// cell's border the surface over a piece of one side may be a neighbour's (drawn beside it, not
// in it): each side's samples are measured against the other side's surface around them — the
// children, or the tile, with the triangles of the other tiles of their depth (and of the leaves
// above it) within `margin` (a sixteenth of the tile's cell) of the samples' box. A distance
// beyond the margin is measured as it is to the triangles within it: never less than the true
// one.
double tile_error(const Node& n, const Tree& tree, const Cube& cube, const TileStore& store, const TilesSettings& s) {
    double child_error = 0;
    bool any_child = false;
    for (int c : n.child)
        if (c >= 0) {
            child_error = std::max(child_error, tree.nodes[size_t(c)].error);
            any_child = any_child || !tree.nodes[size_t(c)].uri.empty();
        }
    if (n.uri.empty() || !any_child) return child_error;
    // The children's triangles, gathered each time they are needed rather than held twice.
    auto gather_children = [&] {
        std::vector<float> xyz;
        for (int c : n.child)
            if (c >= 0 && !tree.nodes[size_t(c)].uri.empty()) {
                const std::vector<float> part = store.get(c);
                xyz.insert(xyz.end(), part.begin(), part.end());
            }
        return xyz;
    };
    const int id = int(&n - tree.nodes.data());
    const std::vector<float> own = store.get(id);
    const double margin = cube.extent / double(1 << n.depth) / 16;
    // `side` and what the viewer draws with the tiles of `depth` around the samples' box.
    auto surface_near = [&](std::vector<float> side, const std::vector<float>& samples, int depth) {
        Box around;  // the samples', y-up
        for (size_t i = 0; i < samples.size(); i += 3) around.add(&samples[i]);
        for (int a = 0; a < 3; ++a) around.min[a] -= margin, around.max[a] += margin;
        // The same box in the model's coordinates (y-up (x, z, -y) back to z-up).
        Box model;
        model.min[0] = around.min[0], model.max[0] = around.max[0];
        model.min[1] = -around.max[2], model.max[1] = -around.min[2];
        model.min[2] = around.min[1], model.max[2] = around.max[1];
        for (size_t o = 0; o < tree.nodes.size(); ++o) {
            const Node& other = tree.nodes[o];
            const bool drawn = other.depth == depth || (other.leaf && other.depth < depth);
            if (!drawn || other.uri.empty() || other.box.empty() || int(o) == id) continue;
            if (std::find(n.child.begin(), n.child.end(), int(o)) != n.child.end()) continue;  // in `side`
            if (other.box.meets(model)) store.append_within(int(o), around, side);
        }
        return side;
    };
    const uint64_t samples = std::max<uint64_t>(10000, own.size() / 9);  // about one a tile triangle
    const double from_tile =
        compare::one_sided_hausdorff(own, surface_near(gather_children(), own, n.depth + 1), samples, s.seed);
    const std::vector<float> children = gather_children();
    const double from_children =
        compare::one_sided_hausdorff(children, surface_near(own, children, n.depth), samples, s.seed);
    return std::max(from_tile, from_children) + child_error;
}

// Sets the errors of `parents` (tiles of one depth, whose children's errors are set) on
// s.threads threads, each tile's on one, so the figures do not depend on the threads. Memory:
// per thread a tile, its children twice (as samples, and with their neighbours' triangles near
// the tile, indexed); the tiles are read back from `store`.
void measure_errors(const std::vector<Node*>& parents, const Tree& tree, const Cube& cube, TileStore& store,
                    const TilesSettings& s, ProgressSink& progress) {
    store.flush();
    std::atomic<size_t> next{0}, done{0};
    std::atomic<bool> stop{false};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    // Measures the next tile; false when none is left or the work stopped.
    auto measure_next = [&] {
        const size_t i = stop.load() ? parents.size() : next.fetch_add(1);
        if (i >= parents.size()) return false;
        try {
            parents[i]->error = tile_error(*parents[i], tree, cube, store, s);
            done.fetch_add(1);
        } catch (...) {
            const std::lock_guard<std::mutex> lock(failure_mutex);
            if (!failure) failure = std::current_exception();
            stop.store(true);
        }
        return true;
    };
    std::vector<std::thread> workers;
    const size_t extra = std::min<size_t>(parents.size(), std::max(1u, s.threads)) - (parents.empty() ? 0 : 1);
    for (size_t t = 0; t < extra; ++t) workers.emplace_back([&] {
        while (measure_next()) {
        }
    });
    // This thread works too, and says how far they are and looks for a cancel between tiles.
    while (measure_next()) {
        progress.update(done.load());
        if (progress.cancelled()) stop.store(true);
    }
    for (std::thread& w : workers) w.join();
    if (failure) std::rethrow_exception(failure);
    throw_if_cancelled(progress);
    progress.update(done.load());
}

Json box_json(const Box& b, double pad) {
    Json j = Json::array();
    double c[3], h[3];
    for (int a = 0; a < 3; ++a) c[a] = (b.min[a] + b.max[a]) / 2, h[a] = (b.max[a] - b.min[a]) / 2 + pad;
    j = {c[0], c[1], c[2], h[0], 0, 0, 0, h[1], 0, 0, 0, h[2]};
    return Json{{"box", j}};
}

}  // namespace

TilesResult tile_file(const TilesSettings& s, ProgressSink& progress) {
    if (s.tile_triangles < kMinTileTriangles)
        throw io::OptionError(Setting::kTileTriangles, mention(Setting::kTileTriangles) + " must be at least " +
                                                            std::to_string(kMinTileTriangles) + ", got " +
                                                            std::to_string(s.tile_triangles));
    if (s.origin && (!(std::fabs(s.origin->latitude) <= 90) || !(std::fabs(s.origin->longitude) <= 180) ||
                     !std::isfinite(s.origin->height) || std::fabs(s.origin->height) > 1e7))
        throw io::OptionError(Setting::kOrigin, mention(Setting::kOrigin) +
                                                    " must be a longitude in -180..180, a latitude in -90..90 and a "
                                                    "height within 10 000 km, got " +
                                                    std::to_string(s.origin->longitude) + "," +
                                                    std::to_string(s.origin->latitude) + "," +
                                                    std::to_string(s.origin->height));
    const fs::path outdir = fs::path(s.outdir).lexically_normal();
    if (outdir.empty() || s.outdir == "-")
        throw io::OptionError(Setting::kOutput, "the output must be a directory, got '" + s.outdir + "'");
    std::error_code ec;
    const bool exists = fs::exists(outdir, ec);
    if (exists && !fs::is_directory(outdir, ec))
        throw io::OptionError(Setting::kOutput, outdir.string() + ": exists and is not a directory");
    if (exists && !fs::is_empty(outdir, ec) && !s.overwrite)
        throw io::OptionError(Setting::kOverwrite, outdir.string() + ": the directory is not empty; its files are kept "
                                                   "unless " + mention(Setting::kOverwrite) + " is given");
    if (fs::path parent = outdir.has_parent_path() ? outdir.parent_path() : fs::path(".");
        ::access(parent.c_str(), W_OK) != 0)
        throw io::Error(outdir.string(), "cannot write here: directory '" + parent.string() +
                                             "' does not exist or is not writable");

    TilesResult result;
    // The tileset is built here, renamed to outdir when complete.
    DirectoryGuard building(make_directory_beside(outdir.string(), "building"));
    // The level meshes and a spooled stdin.
    std::string tmp = s.read.tmpdir.empty() ? (std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") : s.read.tmpdir;
    DirectoryGuard work(make_directory_beside((fs::path(tmp) / "meshstream-tiles").string(), "work"));

    std::string input = s.input;
    std::string input_format = s.input_format;
    std::optional<ConvertResult> spooled;
    if (!is_regular_file(input)) {
        // Read more than once: a pipe is spooled first.
        StepProgress step(progress, "spooling the input");
        ConvertSettings cs;
        cs.input = s.input;
        cs.input_format = s.input_format;
        cs.output = (fs::path(work.path()) / "input.mstream").string();
        cs.output_format = "stream";
        cs.read = s.read;
        spooled = convert_file(cs, step);
        input = cs.output;
        input_format = "stream";
    }

    // The bounding cube: the box of the input's triangles, from its lowest corner, as wide as its
    // longest side. A PLY's box is found from its vertices alone, without reading its faces
    // (input_box); the leaves' sort then finds its triangles' box, and if some vertex no face
    // uses lay outside it, the sort is done again on the triangles' cube.
    auto cube_of = [&](const io::Bounds& b) {
        Cube cube;
        double extent = 0;
        for (int a = 0; a < 3; ++a) {
            cube.origin[a] = b.min[a];
            extent = std::max(extent, double(b.max[a]) - double(b.min[a]));
        }
        if (!(extent >= 0) || !std::isfinite(extent))
            throw io::Error(s.input, "no triangle with finite coordinates: nothing to tile");
        cube.extent = extent > 0 ? extent * (1 + 1e-6) : 1;
        return cube;
    };
    Cube cube;
    InputBox found;
    {
        StepProgress step(progress, "bounds");
        found = input_box(input, input_format, s.read, step, true);
        cube = cube_of(found.box);
    }

    // The leaves: the input sorted by cell while its cells are counted, the octree built from
    // the counts, then each leaf's triangles written at full resolution, and all of them, in
    // cell order, as the first level's input.
    Tree tree;
    TileStore store(work.path());
    TileWriter writer(s, tree, cube, building.path(), outdir.string(), store);
    const std::string sorted_input = (fs::path(work.path()) / "input.sorted.mstream").string();
    std::vector<uint64_t> region;
    double grid_step = 0;  // the quantization grid's step (0: float positions)
    {
        StepProgress step(progress, "leaves");
        CellCounts counts(s.read.memory_budget_bytes * 3 / 16);
        Warnings read;  // what the reader said, of the sort that is kept
        const io::Bounds corners =
            writer.sort(input, input_format, &counts, step, &read, &result, found.vertex_table_bytes);
        if (found.of_vertices && !counts.empty() && (corners.min != found.box.min || corners.max != found.box.max)) {
            cube = cube_of(corners);  // the writer's cube
            counts = CellCounts(s.read.memory_budget_bytes * 3 / 16);
            read = Warnings();
            writer.sort(input, input_format, &counts, step, &read, &result, found.vertex_table_bytes);
        }
        result.warnings.merge(read);
        if (counts.empty()) throw io::Error(s.input, "no triangle to tile");
        const std::vector<std::pair<uint32_t, uint64_t>> cells = counts.sorted();
        tree.build(cells, 0, cells.size(), 0, 0, s.tile_triangles, counts.depth());
        grid_step = writer.set_grid(tree.max_depth);
        region.assign(size_t(std::max(tree.max_depth, 1)), 0);
        writer.write(
            [&](uint32_t key) {
                const int n = tree.at(key, kMaxDepth);
                return n >= 0 && tree.nodes[size_t(n)].leaf ? n : -1;
            },
            &region, step, tree.max_depth > 0 ? sorted_input : std::string());
    }
    release_free_memory();
    const int deepest = tree.max_depth;

    // A spooled input is named as it came, with what its reader found.
    if (spooled) {
        result.input_name = spooled->input_name;
        result.input_format = spooled->input_format;
        result.warnings.merge(spooled->warnings);
    }

    // The levels above, each decimated from the one below as one mesh (the first from the
    // sorted copy of the input).
    const std::set<std::string> input_codes = result.warnings.codes();
    std::string below = sorted_input, below_format = "stream";
    uint64_t below_count = tree.nodes[0].count;
    for (int depth = deepest - 1; depth >= 0; --depth) {
        uint64_t cells_here = 0;
        for (const Node& n : tree.nodes) cells_here += n.depth == depth && !n.leaf;
        // About the budget a cell, and at most a quarter of what the level below has there: a
        // surface's cells of half the size hold a quarter of its area, so each level halves the
        // detail (and the levels above the leaves add at most a third to them).
        const double share = std::min(
            0.25, region[size_t(depth)] > 0 ? double(s.tile_triangles * cells_here) / double(region[size_t(depth)]) : 1);
        const uint64_t target = std::max<uint64_t>(1, uint64_t(std::llround(share * double(below_count))));
        std::string level = below, level_format = below_format;
        if (target < below_count) {
            StepProgress step(progress, "level " + std::to_string(depth));
            DecimateSettings ds;
            ds.input = below;
            ds.input_format = below_format;
            ds.output = (fs::path(work.path()) / ("level" + std::to_string(depth) + ".mstream")).string();
            ds.output_format = "stream";
            ds.target = target;
            ds.threads = s.threads;
            // The decimators' buffers within a third of the memory budget together (about 300
            // bytes a triangle each): a level's order is the cell order, which a smaller
            // buffer follows as well.
            ds.buffer = std::clamp<size_t>(size_t(s.read.memory_budget_bytes / 3 / (300 * std::max(1u, s.threads))),
                                           kMinRangeBuffer, decimate::kDefaultBufferTriangles);
            ds.seed = s.seed;
            ds.read = s.read;
            ds.write.tmpdir = s.read.tmpdir;
            const DecimateResult d = decimate_file(ds, step);
            // What the leaves' pass said of the input (dropped triangles) is not said again by
            // the level read from its copy.
            result.warnings.merge(d.warnings, below == sorted_input ? &input_codes : nullptr);
            level = ds.output;
            level_format = "stream";
            below_count = d.triangles_out;
            release_free_memory();
        }
        std::fill(region.begin(), region.end(), 0);
        StepProgress step(progress, "level " + std::to_string(depth) + " tiles");
        writer.sort(level, level_format, nullptr, step, nullptr, nullptr);
        writer.write(
            [&](uint32_t key) {
                const int n = tree.at(key, depth);
                return n >= 0 && !tree.nodes[size_t(n)].leaf && tree.nodes[size_t(n)].depth == depth ? n : -1;
            },
            &region, step);
        release_free_memory();
        // The level below is no longer needed.
        if (below != level) fs::remove(below, ec);
        below = level, below_format = level_format;

        // The errors of this depth's tiles: to their children's content, plus the children's own.
        step.phase("measuring errors", cells_here);
        std::vector<Node*> parents;
        for (Node& n : tree.nodes)
            if (n.depth == depth && !n.leaf) parents.push_back(&n);
        measure_errors(parents, tree, cube, store, s, step);
        release_free_memory();
    }

    writer.report_notes(result.warnings);

    // The boxes: each tile's content and its children's.
    for (int i = int(tree.nodes.size()) - 1; i >= 0; --i) {
        Node& n = tree.nodes[size_t(i)];
        for (int c : n.child)
            if (c >= 0) n.box.add(tree.nodes[size_t(c)].box);
    }
    // Boxes cover the quantized positions too: a step of the common grid beyond the exact ones.
    const double pad = grid_step > 0 ? grid_step : cube.extent * 1e-7;

    // A tileset file: the tile `root` under the asset, with `error` as the tileset's.
    uint64_t json_bytes = 0;
    auto write_tileset = [&](const fs::path& relative, const Json& root, double error) {
        const Json tileset = {{"asset", {{"version", "1.1"}, {"generator", std::string("meshstream tiles")}}},
                              {"geometricError", error},
                              {"root", root}};
        const fs::path path = fs::path(building.path()) / relative;
        fs::create_directories(path.parent_path());
        std::ofstream f(path);
        f << tileset.dump(1) << '\n';
        f.close();
        if (!f) throw io::Error(path.string(), "cannot write: " + std::string(std::strerror(errno)));
        json_bytes += fs::file_size(path);
        ++result.json_files;
    };
    // The tile `id` and its subtree as JSON in the file of directory `dir` (relative to the
    // tileset's root; URIs are relative to it). A subtree whose root's depth is a multiple of
    // kDepthsPerFile goes to a tileset file of its own (tiles/<depth>/<cell>.json, an external
    // tileset), which its parent's file references from a tile of the same volume and the
    // parent's error (so a viewer that refines the parent refines into it): no file holds
    // more than the tiles of kDepthsPerFile depths and the references below them.
    std::function<Json(int, const fs::path&)> tile_json = [&](int id, const fs::path& dir) {
        const Node& n = tree.nodes[size_t(id)];
        Json t;
        t["boundingVolume"] = box_json(n.box, pad);
        t["geometricError"] = n.error;
        if (!n.uri.empty()) t["content"] = {{"uri", fs::path(n.uri).lexically_relative(dir).generic_string()}};
        Json children = Json::array();
        for (int c : n.child) {
            if (c < 0 || tree.nodes[size_t(c)].box.empty()) continue;
            const Node& child = tree.nodes[size_t(c)];
            if (child.leaf || child.depth % kDepthsPerFile != 0) {
                children.push_back(tile_json(c, dir));
                continue;
            }
            const fs::path file = fs::path("tiles") / std::to_string(child.depth) /
                                  (std::to_string(child.prefix >> (3 * (kMaxDepth - child.depth))) + ".json");
            Json sub = tile_json(c, file.parent_path());
            sub["refine"] = "REPLACE";
            write_tileset(file, sub, child.error);
            Json reference;
            reference["boundingVolume"] = box_json(child.box, pad);
            reference["geometricError"] = n.error;
            reference["content"] = {{"uri", file.lexically_relative(dir).generic_string()}};
            children.push_back(reference);
        }
        if (!children.empty()) t["children"] = children;
        return t;
    };
    Json root = tile_json(0, fs::path("."));
    root["refine"] = "REPLACE";
    if (s.origin) {
        const std::array<double, 16> m = enu_to_ecef(*s.origin);
        root["transform"] = Json(std::vector<double>(m.begin(), m.end()));
    }
    const Node& top = tree.nodes[0];
    result.geometric_error = std::max(top.box.diagonal(), top.error);
    write_tileset("tileset.json", root, result.geometric_error);

    // The figures per depth.
    result.levels.assign(size_t(deepest + 1), TileLevel{});
    for (int d = 0; d <= deepest; ++d) result.levels[size_t(d)].depth = d, result.levels[size_t(d)].min_error = HUGE_VAL;
    for (const Node& n : tree.nodes) {
        if (n.uri.empty()) continue;
        TileLevel& l = result.levels[size_t(n.depth)];
        ++l.tiles;
        l.leaves += n.leaf;
        l.triangles += n.triangles;
        l.bytes += n.bytes;
        l.min_error = std::min(l.min_error, n.error);
        l.max_error = std::max(l.max_error, n.error);
        ++result.tiles;
        result.bytes += n.bytes;
        if (n.leaf) result.leaf_bytes += n.bytes;
    }
    for (TileLevel& l : result.levels)
        if (l.tiles == 0) l.min_error = 0;
    result.bytes += json_bytes;

    // Into place: an existing outdir (allowed by `overwrite`) goes only once the new one is whole.
    throw_if_cancelled(progress);
    if (exists) {
        const std::string old = make_directory_beside(outdir.string(), "replaced");
        DirectoryGuard replaced(old);
        fs::rename(outdir, fs::path(old) / "old");
        fs::rename(building.path(), outdir);
    } else {
        fs::rename(building.path(), outdir);
    }
    building.keep();
    return result;
}

TilesetSummary summarize_tileset(const std::string& tileset_json) {
    TilesetSummary out;
    std::function<void(const fs::path&, const Json&, int)> walk_tile;
    auto load = [&](const fs::path& file) {
        std::ifstream f(file);
        if (!f) throw io::Error(file.string(), "cannot open: " + std::string(std::strerror(errno)));
        Json j;
        try {
            j = Json::parse(f);
        } catch (const Json::exception& e) {
            throw io::Error(file.string(), std::string("not a tileset: ") + e.what());
        }
        if (!j.is_object() || !j.contains("root") || !j["root"].is_object())
            throw io::Error(file.string(), "not a tileset: no root tile");
        ++out.json_files;
        out.bytes += fs::file_size(file);
        return j;
    };
    walk_tile = [&](const fs::path& file, const Json& t, int depth) {
        int child_depth = depth;
        if (t.contains("content") && t["content"].contains("uri")) {
            const fs::path target = file.parent_path() / t["content"]["uri"].get<std::string>();
            if (target.extension() == ".json") {
                const Json sub = load(target);
                walk_tile(target, sub["root"], depth);
            } else {
                if (out.levels.size() <= size_t(depth)) {
                    out.levels.resize(size_t(depth) + 1);
                    out.levels[size_t(depth)].depth = depth;
                    out.levels[size_t(depth)].min_error = HUGE_VAL;
                }
                TileLevel& l = out.levels[size_t(depth)];
                uint64_t triangles = 0;
                {
                    io::Input in = io::open_input(target.string(), {}, {});
                    triangles = in.reader->header().triangle_count.value_or(0);
                }
                const double e = t.value("geometricError", 0.0);
                ++l.tiles;
                l.leaves += !t.contains("children") || t["children"].empty();
                l.triangles += triangles;
                l.bytes += fs::file_size(target);
                l.min_error = std::min(l.min_error, e);
                l.max_error = std::max(l.max_error, e);
                ++out.tiles;
                out.triangles += triangles;
                out.bytes += fs::file_size(target);
                child_depth = depth + 1;
            }
        }
        if (t.contains("children"))
            for (const Json& c : t["children"]) walk_tile(file, c, child_depth);
    };
    const fs::path file(tileset_json);
    const Json j = load(file);
    out.version = j.contains("asset") ? j["asset"].value("version", "") : "";
    out.geometric_error = j.value("geometricError", 0.0);
    out.placed = j["root"].contains("transform");
    walk_tile(file, j["root"], 0);
    for (TileLevel& l : out.levels)
        if (l.tiles == 0) l.min_error = 0;
    return out;
}

}  // namespace meshstream::engine
