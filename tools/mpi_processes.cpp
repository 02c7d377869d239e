// The messages of a job spread over MPI ranks: see mpi_processes.hpp.
//
// Rank r > 0 sends rank 0, in this order: kChunk messages (a ChunkHeader, then the chunk's
// triangles as io::TriangleRecords: 36 bytes of positions each, and the channels carried) and kProgress messages (the
// range's triangles decimated so far), then one kClose (a CloseHeader, then the exception's message when it failed).
// Rank 0 may send it kStop at any time (its range is to stop between chunks), and sends every rank it received from one
// kDone once it has everything: a rank leaves only then, with no message of it in flight.
#include "tools/mpi_processes.hpp"

#include "io/endian.hpp"
#include "io/triangle_records.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace meshstream::tools {
namespace {

using engine::Piece;
using engine::RangeOutcome;
using engine::RangePlan;
using engine::RangeSink;

enum Tag : int { kChunk = 1, kProgress, kClose, kStop, kDone };

struct ChunkHeader {
    double weight = 1;
    uint64_t triangles = 0;
    Piece piece = Piece::kInterior;
};

struct CloseHeader {
    RangeOutcome outcome;
    bool failed = false;
};

// The plan as broadcast: whether there is one, and it.
struct PlanMessage {
    bool has_plan = false;
    RangePlan plan;
};

static_assert(std::is_trivially_copyable_v<ChunkHeader> && std::is_trivially_copyable_v<CloseHeader> &&
                  std::is_trivially_copyable_v<PlanMessage>,
              "sent as bytes between ranks of one build");

// A message out of protocol (a rank of another build?) or a failed MPI call: the job cannot go
// on, and a rank waiting for another would wait for ever. Every rank is ended, with the reason.
[[noreturn]] void abort_job(const std::string& what) {
    std::fprintf(stderr, "meshstream-mpi: error: MPI: %s\n", what.c_str());
    MPI_Abort(MPI_COMM_WORLD, 1);
    std::abort();
}

void check(int status, const char* what) {
    if (status != MPI_SUCCESS) abort_job(std::string(what) + " failed");
}

// A message's header, as the sending rank wrote it (io::ByteWriter::raw).
template <typename T>
T read_header(const std::vector<char>& in) {
    io::ByteReader reader(in.data(), in.size());
    const T value = reader.raw<T>();
    if (!reader.ok()) abort_job("a rank's message is shorter than its header");
    return value;
}

void send_bytes(const void* bytes, size_t n, int to, Tag tag) {
    check(MPI_Send(bytes, int(n), MPI_BYTE, to, tag, MPI_COMM_WORLD), "MPI_Send");
}

// Waits for `request` without spinning: a rank that waits (for the plan, for rank 0's kDone)
// leaves its core to the ranks that work, on a machine whose cores the job shares.
void wait_idle(MPI_Request& request) {
    for (;;) {
        int done = 0;
        check(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "MPI_Test");
        if (done) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
}

// The message's text of an exception; a library error's with its settings' mentions, which rank
// 0 renders as it renders its own.
std::string message_of(const std::exception_ptr& error) {
    try {
        std::rethrow_exception(error);
    } catch (const meshstream::Error& e) {
        return e.raw_what();
    } catch (const std::exception& e) {
        return e.what();
    } catch (...) {
        return "unknown error";
    }
}

// Rank r's sink: every call a message to rank 0. Between chunks it looks for rank 0's kStop.
class SendingSink final : public RangeSink {
public:
    SendingSink(std::atomic<bool>& stop, const io::Channels& channels) : stop_(stop), codec_(channels) {}
    void append(const io::TriangleChunk& chunk, double weight, Piece piece) override {
        io::ByteWriter message;
        message.raw(ChunkHeader{weight, chunk.size(), piece});
        records_.clear();
        codec_.encode(chunk, records_);
        message.raw_bytes(records_.data(), records_.size());
        send_bytes(message.data(), message.size(), 0, kChunk);
        look_for_stop();
    }
    void progress(uint64_t decimated) override {
        io::ByteWriter message;
        message.raw(decimated);
        send_bytes(message.data(), message.size(), 0, kProgress);
        look_for_stop();
    }
    void close(const RangeOutcome& outcome, std::exception_ptr error) override {
        io::ByteWriter message;
        message.raw(CloseHeader{outcome, error != nullptr});
        if (error) {
            const std::string text = message_of(error);
            message.raw_bytes(text.data(), text.size());
        }
        send_bytes(message.data(), message.size(), 0, kClose);
    }

private:
    void look_for_stop() {
        int flag = 0;
        check(MPI_Iprobe(0, kStop, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE), "MPI_Iprobe");
        if (flag) stop_ = true;
    }
    std::atomic<bool>& stop_;
    io::TriangleRecords codec_;
    std::vector<char> records_;
};

}  // namespace

MpiProcesses::MpiProcesses() {
    int provided = 0, size = 1, rank = 0;
    check(MPI_Query_thread(&provided), "MPI_Query_thread");
    if (provided < MPI_THREAD_SERIALIZED)
        abort_job("this MPI library gives no MPI_THREAD_SERIALIZED, which rank 0 needs");
    check(MPI_Comm_size(MPI_COMM_WORLD, &size), "MPI_Comm_size");
    check(MPI_Comm_rank(MPI_COMM_WORLD, &rank), "MPI_Comm_rank");
    count_ = unsigned(size);
    rank_ = unsigned(rank);
}

void MpiProcesses::share_plan(const std::optional<RangePlan>& plan) {
    PlanMessage message;
    message.has_plan = plan.has_value();
    if (plan) message.plan = *plan;
    others_waiting_ = plan && plan->ranges > 1;
    MPI_Request request;
    check(MPI_Ibcast(&message, int(sizeof message), MPI_BYTE, 0, MPI_COMM_WORLD, &request), "MPI_Ibcast");
    wait_idle(request);
}

std::optional<RangePlan> MpiProcesses::receive_plan() {
    PlanMessage message;
    MPI_Request request;
    check(MPI_Ibcast(&message, int(sizeof message), MPI_BYTE, 0, MPI_COMM_WORLD, &request), "MPI_Ibcast");
    wait_idle(request);
    if (!message.has_plan) return std::nullopt;
    return message.plan;
}

void MpiProcesses::receive(std::span<RangeSink* const> sinks, std::atomic<bool>& stop, const io::Channels& channels) {
    const io::TriangleRecords records(channels);
    std::vector<bool> open(sinks.size(), true);
    size_t still_open = sinks.size();
    bool stop_sent = false;
    std::vector<char> bytes;
    // A sink that fails (rank 0's --tmpdir full) stops the job; the ranks' messages are still
    // received to the end, so that every rank leaves, and the failure is thrown then.
    std::exception_ptr failure;
    auto deliver = [&](const auto& put) {
        if (failure) return;
        try {
            put();
        } catch (...) {
            failure = std::current_exception();
            stop = true;
        }
    };
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (still_open > 0) {
        if (stop && !stop_sent) {
            for (size_t i = 0; i < sinks.size(); ++i)
                if (open[i]) check(MPI_Send(nullptr, 0, MPI_BYTE, int(i + 1), kStop, MPI_COMM_WORLD), "MPI_Send");
            stop_sent = true;
        }
        MPI_Status status;
        int flag = 0;
        check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "MPI_Iprobe");
        if (!flag) {
            // Polled rather than blocked in MPI_Recv, so that a stop is passed on at once.
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            continue;
        }
        int size = 0;
        check(MPI_Get_count(&status, MPI_BYTE, &size), "MPI_Get_count");
        bytes.resize(size_t(size));
        check(MPI_Recv(bytes.data(), size, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
                       MPI_STATUS_IGNORE),
              "MPI_Recv");
        const size_t from = size_t(status.MPI_SOURCE);
        if (from == 0 || from > sinks.size() || !open[from - 1])
            abort_job("a message from rank " + std::to_string(from) + ", which has no open range");
        RangeSink& sink = *sinks[from - 1];
        switch (status.MPI_TAG) {
            case kChunk: {
                const auto header = read_header<ChunkHeader>(bytes);
                if (bytes.size() != sizeof header + header.triangles * records.bytes())
                    abort_job("rank " + std::to_string(from) + " sent a chunk of the wrong size");
                if (chunk.capacity() < header.triangles) chunk = io::TriangleChunk(size_t(header.triangles), channels);
                records.decode(bytes.data() + sizeof header, size_t(header.triangles), chunk);
                deliver([&] { sink.append(chunk, header.weight, header.piece); });
                break;
            }
            case kProgress: sink.progress(read_header<uint64_t>(bytes)); break;
            case kClose: {
                const auto header = read_header<CloseHeader>(bytes);
                std::exception_ptr error;
                if (header.failed)
                    error = std::make_exception_ptr(
                        meshstream::Error(std::string(bytes.begin() + sizeof header, bytes.end())));
                // A range that failed, or stopped at a forced write, stops the others (as one
                // thread's does on one machine).
                if (header.failed || header.outcome.forced) stop = true;
                sink.close(header.outcome, error);
                open[from - 1] = false;
                --still_open;
                break;
            }
            default: abort_job("rank " + std::to_string(from) + " sent an unknown message");
        }
    }
    for (size_t i = 0; i < sinks.size(); ++i)
        check(MPI_Send(nullptr, 0, MPI_BYTE, int(i + 1), kDone, MPI_COMM_WORLD), "MPI_Send");
    others_waiting_ = false;
    if (failure) std::rethrow_exception(failure);
}

void MpiProcesses::send(const io::Channels& channels,
                        const std::function<void(RangeSink&, std::atomic<bool>& stop)>& run_range) {
    std::atomic<bool> stop{false};
    SendingSink sink(stop, channels);
    run_range(sink, stop);
    // Rank 0's kStop, if it sent one, and its kDone.
    for (;;) {
        MPI_Request request;
        MPI_Status status;
        check(MPI_Irecv(nullptr, 0, MPI_BYTE, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &request), "MPI_Irecv");
        for (int done = 0;;) {
            check(MPI_Test(&request, &done, &status), "MPI_Test");
            if (done) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        if (status.MPI_TAG == kDone) return;
    }
}

}  // namespace meshstream::tools
