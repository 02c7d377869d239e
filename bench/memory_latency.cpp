// Random-access cost of this machine's memory, for reading the decimator's profile: the
// in-core buffer (about 60 MB at the default 400 000 triangles) is read at random, so what a
// cache line costs there decides how fast a collapse can be. For each working-set size, a
// pointer chase through randomly ordered 64-byte lines (each load waits for the one before:
// the latency) and 8, 16 and 32 independent chases in lockstep (the loads overlap: the cost per
// line when that many misses are in flight together, as with the decimator's batched prefetches),
// and 8 chases through the first lines of 128-byte pairs, reading only those or also the
// second line of each pair (as a 128-byte vertex slot is read): whether a second line of the
// same pair costs another miss.
//
//   memory_latency [MiB...]        default sizes: 1 2 4 16 64 256
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <vector>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace {

struct alignas(64) Line {
    uint64_t next;
    char pad[56];
};

double ns_per_step(std::chrono::steady_clock::time_point t0, size_t steps) {
    return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / double(steps);
}

// K chases in lockstep through the same ring, started K equal steps apart: ns per line
// (with kPair, per line chased, each step also reading the line's 128-byte-pair partner).
template <int K, bool kPair = false>
double chases(const Line* lines, const std::vector<uint64_t>& order, size_t steps, uint64_t& sink) {
    const size_t n = order.size();
    uint64_t q[K];
    for (int k = 0; k < K; ++k) q[k] = order[(k * n) / K];
    const auto t0 = std::chrono::steady_clock::now();
    for (size_t i = 0; i < steps / K; ++i)
        for (int k = 0; k < K; ++k) {
            if constexpr (kPair) sink += lines[q[k] ^ 1].next;
            q[k] = lines[q[k]].next;
        }
    const double ns = ns_per_step(t0, steps);
    for (int k = 0; k < K; ++k) sink ^= q[k];
    return ns;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<size_t> sizes;
    for (int i = 1; i < argc; ++i) {
        char* end = nullptr;
        const unsigned long mib = std::strtoul(argv[i], &end, 10);
        if (end == argv[i] || *end != '\0' || mib == 0 || mib > 65536) {
            std::fprintf(stderr, "memory_latency: '%s' is not a size in MiB (1..65536)\n", argv[i]);
            return 2;
        }
        sizes.push_back(mib);
    }
    if (sizes.empty()) sizes = {1, 2, 4, 16, 64, 256};
    std::printf(
        "working set   dependent   per line with 8, 16 and 32 chases in lockstep   "
        "per pair with 8: one line, both\n");
    for (const size_t mib : sizes) {
        const size_t n = mib * (size_t{1} << 20) / sizeof(Line);
        // 2 MiB aligned and advised as huge pages, like the decimator's pools (so that TLB
        // misses do not count twice).
        constexpr size_t kHuge = size_t{2} << 20;
        const size_t bytes = (n * sizeof(Line) + kHuge - 1) / kHuge * kHuge;
        auto* lines = static_cast<Line*>(std::aligned_alloc(kHuge, bytes));
        if (lines == nullptr) {
            std::fprintf(stderr, "memory_latency: cannot allocate %zu MiB\n", mib);
            return 1;
        }
#ifdef __linux__
        madvise(lines, bytes, MADV_HUGEPAGE);
#endif
        std::vector<uint64_t> order(n);
        std::iota(order.begin(), order.end(), uint64_t{0});
        std::shuffle(order.begin(), order.end(), std::mt19937_64(1));
        for (size_t i = 0; i < n; ++i) lines[order[i]].next = order[(i + 1) % n];

        const size_t steps = 20'000'000;
        uint64_t p = order[0];
        auto t0 = std::chrono::steady_clock::now();
        for (size_t i = 0; i < steps; ++i) p = lines[p].next;
        const double dependent = ns_per_step(t0, steps);

        uint64_t sink = p;
        const double c8 = chases<8>(lines, order, steps, sink);
        const double c16 = chases<16>(lines, order, steps, sink);
        const double c32 = chases<32>(lines, order, steps, sink);
        // A ring through the first line of each 128-byte pair (the second lines are never
        // chased, so reading them cannot warm the ring).
        std::vector<uint64_t> pairs(n / 2);
        for (size_t i = 0; i < pairs.size(); ++i) pairs[i] = 2 * i;
        std::shuffle(pairs.begin(), pairs.end(), std::mt19937_64(2));
        for (size_t i = 0; i < pairs.size(); ++i) lines[pairs[i]].next = pairs[(i + 1) % pairs.size()];
        const double pair_one = chases<8>(lines, pairs, steps, sink);
        const double pair_both = chases<8, true>(lines, pairs, steps, sink);
        // Printing the end points keeps the chases from being optimized away.
        std::printf("%6zu MiB     %7.1f ns   %7.1f ns   %7.1f ns   %7.1f ns   %7.1f ns   %7.1f ns   (%llu)\n", mib,
                    dependent, c8, c16, c32, pair_one, pair_both, static_cast<unsigned long long>(sink & 1));
        std::free(lines);
    }
    return 0;
}
