// RangeProcesses over MPI (meshstream-mpi): every rank of MPI_COMM_WORLD is one process of the
// job. Rank 0 broadcasts the plan; rank r decimates range r-1 and sends its pieces to rank 0 in
// point-to-point messages, as it makes them; rank 0 spools them for the seam pass (on its own
// disk: the other ranks need only read the input). Only this file and mpi_main.cpp see MPI.
#pragma once

#include "engine/ranges.hpp"

#include <mpi.h>

namespace meshstream::tools {

class MpiProcesses final : public engine::RangeProcesses {
public:
    // MPI_COMM_WORLD, once MPI is initialized with at least MPI_THREAD_SERIALIZED (rank 0 receives
    // on a thread of its own while its first thread does no MPI).
    MpiProcesses();
    unsigned count() const override { return count_; }
    unsigned rank() const override { return rank_; }
    void share_plan(const std::optional<engine::RangePlan>& plan) override;
    std::optional<engine::RangePlan> receive_plan() override;
    void receive(std::span<engine::RangeSink* const> sinks, std::atomic<bool>& stop,
                 const io::Channels& channels) override;
    void send(const io::Channels& channels,
              const std::function<void(engine::RangeSink&, std::atomic<bool>& stop)>& run_range) override;
    // Rank 0: other ranks were given ranges and have not been released (the job failed before
    // receive() could run to its end); they can only be ended with MPI_Abort.
    bool others_waiting() const { return others_waiting_; }

private:
    unsigned count_ = 1, rank_ = 0;
    bool others_waiting_ = false;
};

}  // namespace meshstream::tools
