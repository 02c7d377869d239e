// Optional time breakdown of the decimator by phase, for speed work (bench/decimate_phases.sh).
// Compiled in only with -DMESHSTREAM_PHASE_TIMERS=ON; otherwise PhaseTimer is an empty object
// and nothing is measured. cachegrind (bench/decimate_costs.sh) counts instructions and misses
// exactly but not what a miss costs; these timers show where the time goes on real hardware.
// On x86 they read the time-stamp counter (a few cycles per scope, so even the 3.6 million
// ratings of a 1 M-triangle run are timed without distorting them much).
#pragma once

#include <cstdint>
#include <cstdio>

#if MESHSTREAM_PHASE_TIMERS
#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#else
#include <chrono>
#endif
#endif

namespace meshstream::decimate {

enum class Phase : int {
    kRead,      // READ: add_triangle (welding, quadrics, connectivity)
    kQueue,     // DECIMATE: queue upkeep, popping and rating edges (includes kRate, kValidate, kApply)
    kRate,      // collapse_placement (quadric sum, 3×3 solve, errors)
    kValidate,  // collapse_valid (fan, link condition, fold checks)
    kApply,     // apply_collapse
    kWrite,     // WRITE: picking and writing one triangle
    kCount
};

#if MESHSTREAM_PHASE_TIMERS
inline uint64_t phase_ticks() {
#if defined(__x86_64__) || defined(__i386__)
    return __rdtsc();
#else
    return static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
}

struct PhaseTotals {
    uint64_t ticks[int(Phase::kCount)] = {};
    uint64_t calls[int(Phase::kCount)] = {};
    uint64_t first = 0;  // ticks at the first timed scope
};
inline PhaseTotals g_phase_totals;  // single-threaded use (one decimator per process)

class PhaseTimer {
public:
    explicit PhaseTimer(Phase phase) : phase_(phase), start_(phase_ticks()) {
        if (g_phase_totals.first == 0) g_phase_totals.first = start_;
    }
    ~PhaseTimer() {
        g_phase_totals.ticks[int(phase_)] += phase_ticks() - start_;
        ++g_phase_totals.calls[int(phase_)];
    }
    PhaseTimer(const PhaseTimer&) = delete;
    PhaseTimer& operator=(const PhaseTimer&) = delete;

private:
    Phase phase_;
    uint64_t start_;
};

// Prints each phase's calls, ticks per call and share of the ticks since the first timed
// scope (queue upkeep without the phases it contains, so the shares add up).
inline void print_phase_report(std::FILE* out) {
    const PhaseTotals& t = g_phase_totals;
    const double total = double(phase_ticks() - t.first);
    static const char* const names[] = {"read", "queue", "rate", "validate", "apply", "write"};
    std::fprintf(out, "phase timers (time-stamp counter ticks):\n");
    double covered = 0;
    for (int i = 0; i < int(Phase::kCount); ++i) {
        double ticks = double(t.ticks[i]);
        if (i == int(Phase::kQueue))
            ticks -= double(t.ticks[int(Phase::kRate)] + t.ticks[int(Phase::kValidate)] + t.ticks[int(Phase::kApply)]);
        covered += ticks;
        std::fprintf(out, "  %-9s %11llu calls %9.0f ticks/call %5.1f %%\n", names[i],
                     static_cast<unsigned long long>(t.calls[i]), t.calls[i] ? ticks / double(t.calls[i]) : 0.0,
                     total > 0 ? 100 * ticks / total : 0.0);
    }
    std::fprintf(out, "  %-9s %53.1f %%\n", "other", total > 0 ? 100 * (total - covered) / total : 0.0);
}
#else
class PhaseTimer {
public:
    explicit PhaseTimer(Phase) {}
};
inline void print_phase_report(std::FILE*) {}
#endif

}  // namespace meshstream::decimate
