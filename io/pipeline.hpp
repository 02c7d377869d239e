// Reading and writing on threads of their own, beside the caller's: ReadAhead runs a
// TriangleInput's next() on a reader thread (inflating, parsing, welding an indexed file's
// vertices, the bad-triangle policy) and WriteBehind an Output's write() on a writer thread
// (formatting, a writer's weld, encoding, deflating). Each hands chunks over a bounded queue in
// stream order; the chunks change hands by swapping their storage, never by copying.
//
// The output is the same, byte for byte, as with the calls made on the caller's thread: the
// same chunks reach the same calls in the same order. An exception on either thread is the one
// the call would have thrown (the same io::Error, with file and position), rethrown on the
// caller's thread once that thread has ended; the caller then unwinds as without threads (an
// Output destroyed unfinished leaves nothing). Output::finish(), which commits the file, stays
// on the caller's thread.
//
// Memory: kPipelineChunks chunks of the capacity given, counting the caller's own (four chunks
// of the default 16 384 triangles hold 2.25 MiB of positions, plus the channels carried); the
// reader's and writer's own tables are as without threads.
#pragma once

#include "io/format.hpp"
#include "io/input_count.hpp"
#include "io/triangle_input.hpp"

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace meshstream::io {

// Chunks a ReadAhead or a WriteBehind keeps in all, counting the caller's own: one being filled,
// one being consumed, two waiting to absorb the two sides' unevenness.
inline constexpr size_t kPipelineChunks = 4;

// One chunk in a pipeline's queue, with what the reader knew when it handed the chunk over.
struct PipelineSlot {
    PipelineSlot(size_t capacity, const Channels& channels) : chunk(capacity, channels) {}
    TriangleChunk chunk;
    InputCount count;            // the input's count after this chunk (ReadAhead)
    uint64_t stored_offset = 0;  // bytes of the file as stored read by then (ReadAhead)
};

// The bounded hand-over between one producer thread and one consumer thread: slots allocated
// once move between a free list and a full list, in order. A failure is recorded once and
// rethrown: to the consumer after the chunks handed over before it (a reader's error comes in
// stream order), to the producer at its next call (a writer's error stops the stream).
class ChunkQueue {
public:
    ChunkQueue(size_t slots, size_t capacity, const Channels& channels);

    // Producer: an empty slot to fill; null once stop() was called. Rethrows a failure.
    PipelineSlot* get_free();
    // Producer: hands a filled slot over.
    void put_full(PipelineSlot* slot);
    // Producer: the stream ended; get_full() returns null after the last slot.
    void close();
    // Consumer: the next filled slot; null at the end or once stop() was called. Rethrows a
    // failure once the slots handed over before it are taken.
    PipelineSlot* get_full();
    // Consumer: returns a slot for refilling.
    void put_free(PipelineSlot* slot);
    // Rethrows the failure recorded, if any (for the owner, once its thread has ended).
    void rethrow_failure();

    // Either side: records the first failure and wakes the other.
    void fail(std::exception_ptr error);
    // Makes both sides' get_*() return null (the owner then joins its thread).
    void stop();

private:
    std::vector<std::unique_ptr<PipelineSlot>> storage_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<PipelineSlot*> free_, full_;
    bool closed_ = false, stopped_ = false;
    std::exception_ptr error_;
};

class ReadAhead {
public:
    // Starts reading `in` on a thread of its own into chunks of `capacity` triangles with
    // `channels` (kPipelineChunks - 1 of them; the caller's is the last). From here until next() returns false or
    // throws, or this is destroyed, the reader thread owns `in`: the caller must not call it (read stored_size() and
    // the header before).
    ReadAhead(TriangleInput& in, size_t capacity, const Channels& channels);
    // Stops the reader after the chunk it is reading and joins it.
    ~ReadAhead();
    ReadAhead(const ReadAhead&) = delete;
    ReadAhead& operator=(const ReadAhead&) = delete;

    // As TriangleInput::next: swaps the next chunk read into `chunk` (made with the capacity
    // and channels given above) and returns true; returns false at the end, `chunk` cleared.
    // Rethrows the reader's exception after the chunks read before it. Once it returned false
    // or threw, the reader thread has ended and `in` is the caller's again (counts, header).
    bool next(TriangleChunk& chunk);
    // As of the last chunk next() gave: the input's count and ByteSource::stored_offset().
    const InputCount& count() const { return count_; }
    uint64_t stored_offset() const { return stored_offset_; }

private:
    void join();

    ChunkQueue queue_;
    InputCount count_;
    uint64_t stored_offset_ = 0;
    std::thread thread_;
};

// ReadAhead for a reader that gives its vertices and faces apart (Reader::indexed(): PLY), where
// looking the corners up in its vertex table is most of the reading: the reader thread reads the
// faces' indices a batch at a time (a chunk's capacity) and looks up the corners of every other
// batch; a second thread looks up the rest, through a second way to the vertices with a cache of
// its own (IndexedSource::split_lookup: a table read from a file gives it half of its budget).
// next() hands the chunks over in file order, the policy applied and counted by `in` as its
// next() does: the same triangles in the same order, in chunks cut at other places. An error
// (the reader's, a lookup's, a refused triangle) comes after the batches before its own, as
// next()'s comes after the chunks before it.
// Memory: kPipelineChunks batches of `capacity` triangles (their indices and chunks), counting
// the caller's own chunk, as ReadAhead's.
class IndexedReadAhead {
public:
    // True when `in` can be read so: its reader gives its IndexedSource (untouched), and
    // `channels`, what the chunks carry, holds no per-triangle channel.
    static bool possible(TriangleInput& in, const Channels& channels);
    // Starts reading `in` (possible()) into chunks of `capacity` triangles with `channels`;
    // `stored` is what the reader stores of each vertex, ReadOptions::channels of its header's
    // (IndexedSource::vertex's records). As with ReadAhead, the caller must not call `in` until
    // next() returned false or threw, or this is destroyed.
    IndexedReadAhead(TriangleInput& in, size_t capacity, const Channels& channels, const Channels& stored);
    // Stops the threads after the batch each is on and joins them.
    ~IndexedReadAhead();
    IndexedReadAhead(const IndexedReadAhead&) = delete;
    IndexedReadAhead& operator=(const IndexedReadAhead&) = delete;

    // As ReadAhead::next.
    bool next(TriangleChunk& chunk);
    const InputCount& count() const { return in_.count(); }
    uint64_t stored_offset() const { return stored_offset_; }

private:
    enum class State : uint8_t { kFree, kRead, kResolved, kEnd, kFailed };
    struct Batch {
        uint64_t seq = 0;  // the batch's number in the file
        State state = State::kFree;
        std::vector<uint32_t> indices;
        std::vector<TriangleChunk> chunks;  // its triangles, `used` of them (more than one only past a
        size_t used = 0, taken = 0;         // chunk's capacity, as a large polygon makes); `taken` by next()
        uint64_t stored_offset = 0;
        std::exception_ptr error;
    };
    template <class Lookup>
    void resolve(Batch& b, Lookup& lookup);
    Batch& batch(uint64_t seq) { return batches_[seq % batches_.size()]; }
    // Waits until batch `seq` is in one of the states `done` says, or stop; false on stop.
    template <class Done>
    bool wait_for(uint64_t seq, Done done);
    void set(Batch& b, State state);
    void read_faces();
    void resolve_odd();
    void join();

    TriangleInput& in_;
    IndexedSource& source_;
    std::unique_ptr<VertexLookup> lookup_;  // the second thread's
    size_t capacity_;
    Channels channels_;
    CornerLayout layout_;
    std::vector<Batch> batches_;
    std::mutex mutex_;
    std::condition_variable changed_;
    bool stopped_ = false;
    uint64_t next_seq_ = 0;  // the batch next() is on
    uint64_t stored_offset_ = 0;
    std::thread reader_, resolver_;
};

class WriteBehind {
public:
    // Starts a writer thread that writes to `out` chunks of `capacity` triangles with
    // `channels`. Until close() returned or threw, or this is destroyed, the writer thread owns
    // `out`: the caller must not call it.
    WriteBehind(Output& out, size_t capacity, const Channels& channels);
    // Stops the writer after the chunk it is writing and joins it; `out` is left unfinished
    // (discarded when it is destroyed, as without threads).
    ~WriteBehind();
    WriteBehind(const WriteBehind&) = delete;
    WriteBehind& operator=(const WriteBehind&) = delete;

    // As Output::write: hands `chunk`'s triangles to the writer thread, swapping its storage
    // with an emptied chunk of the writer's (`chunk`, made with the capacity and channels given
    // above, comes back cleared). Waits while every chunk is queued. Rethrows the writer's
    // exception (the first write that failed) once the writer thread has ended.
    void write(TriangleChunk& chunk);
    // Waits until every chunk handed over is written and joins the writer thread; rethrows its
    // exception. `out` is then the caller's again (update_materials, finish). Once only.
    void close();

private:
    void join();

    ChunkQueue queue_;
    std::thread thread_;
};

}  // namespace meshstream::io
