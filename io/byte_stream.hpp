// Byte streams under every reader and writer: files, stdin/stdout ("-") and gzip (zlib) on
// both sides. Sources are buffered (1 MiB refills) and give parsers a contiguous window so
// they can tokenize in place; gzip input is recognised by its magic bytes 1f 8b whatever the
// name. Sinks write to a temporary file beside the target and rename it into place on
// commit(), so a failed run never leaves a half-written file under the target's name.
// Offsets and sizes are 64-bit throughout (files over 4 GiB work).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace meshstream::io {

// The unbuffered producer under a ByteSource (a file descriptor, a zlib stream, or a test
// double that fakes huge sizes). read() returns 0 only at end of stream; throws io::Error.
class RawInput {
public:
    virtual ~RawInput() = default;
    virtual size_t read(void* dst, size_t n) = 0;
    // Total size in bytes when known before reading (regular uncompressed files).
    virtual std::optional<uint64_t> size() const { return std::nullopt; }
    // The file as stored, for progress: bytes taken from it so far (compressed bytes under
    // gzip) and its size when it is a regular file (compressed or not).
    virtual uint64_t stored_offset() const { return 0; }
    virtual std::optional<uint64_t> stored_size() const { return size(); }
    // Moves to byte `offset` when the input can seek (a regular file); false when it cannot.
    virtual bool seek(uint64_t offset) {
        (void)offset;
        return false;
    }
};

class ByteSource {
public:
    static constexpr size_t kBufferBytes = size_t{1} << 20;

    // Opens `path` ("-" = stdin). Gzip is detected by magic bytes and decoded transparently.
    // Throws io::Error when the file cannot be opened.
    static std::unique_ptr<ByteSource> open(const std::string& path);
    // Wraps any RawInput (tests, in-memory data). Gzip is detected here too.
    ByteSource(std::unique_ptr<RawInput> raw, std::string name);
    ~ByteSource();
    ByteSource(const ByteSource&) = delete;
    ByteSource& operator=(const ByteSource&) = delete;

    // Copies up to n bytes into dst; returns fewer only at end of stream.
    size_t read(void* dst, size_t n);
    // Returns up to n (<= kBufferBytes) buffered bytes without consuming them; fewer only at
    // end of stream.
    std::span<const std::byte> peek(size_t n);
    // The currently buffered bytes (refilling when empty); empty only at end of stream.
    std::span<const std::byte> window();
    // Consumes n bytes of the current window (n <= window().size()).
    void consume(size_t n);
    // Skips n bytes; returns how many were skipped (fewer only at end of stream).
    uint64_t skip(uint64_t n);
    // Moves to byte `offset` of a plain regular file (not gzip), dropping the buffered bytes,
    // and returns true; returns false, moving nothing, for any other source.
    bool seek(uint64_t offset);
    bool at_end();

    // Bytes consumed so far (of the decoded stream for gzip).
    uint64_t offset() const { return offset_; }
    // Decoded total size when known up front: plain regular files only.
    std::optional<uint64_t> size() const;
    // How far through the file as stored, for progress with any format: bytes read from it so
    // far (compressed bytes for gzip; up to a buffer ahead of offset()), and its size when it
    // is a regular file, gzip or not. Same thread as the reads.
    uint64_t stored_offset() const { return raw_->stored_offset(); }
    std::optional<uint64_t> stored_size() const { return raw_->stored_size(); }
    const std::string& name() const { return name_; }
    bool gzip() const { return gzip_; }
    // The filesystem path when the source is a plain (not gzip) regular file, for readers that
    // read parts of it in place; empty otherwise.
    const std::string& regular_file_path() const { return regular_path_; }

    // Throws io::Error at the current offset (helper for readers).
    [[noreturn]] void fail(const std::string& message) const;

private:
    bool fill(size_t want);  // makes at least `want` bytes buffered if the stream has them

    std::unique_ptr<RawInput> raw_;
    std::string name_;
    std::string regular_path_;
    bool gzip_ = false;
    std::unique_ptr<std::byte[]> buf_;  // kBufferBytes, left uninitialised (opening stays cheap)
    size_t begin_ = 0, end_ = 0;
    uint64_t offset_ = 0;
    bool eof_ = false;
};

struct SinkOptions {
    // zlib level 0–9 when the output is gzip-compressed; -1 = not compressed.
    int gzip_level = -1;
};

// True for "-", /dev/stdout and the like, and existing pipes, devices and sockets: what can be
// read (or written) once only.
bool is_stream(const std::string& path);

// The consumer under every writer. Writes go to `<target>.tmp-XXXXXX` in the target's
// directory; commit() flushes and renames into place, keeping a replaced file's permissions;
// a sink destroyed without commit() deletes its temporary file. A symbolic link is followed
// (the file it names is replaced). Stdout ("-"), the descriptors /dev/stdout, /dev/fd/N and
// the like name, and existing devices, FIFOs and sockets are written in place: nothing can be
// renamed over them.
class ByteSink {
public:
    static constexpr size_t kBufferBytes = size_t{1} << 20;

    // Throws io::Error when the temporary file cannot be created.
    static std::unique_ptr<ByteSink> open(const std::string& path, const SinkOptions& options = {});
    ~ByteSink();
    ByteSink(const ByteSink&) = delete;
    ByteSink& operator=(const ByteSink&) = delete;

    void write(const void* data, size_t n);
    void write(std::string_view s) { write(s.data(), s.size()); }
    // Bytes written so far (uncompressed).
    uint64_t offset() const { return offset_; }
    // True when earlier bytes can be overwritten with patch(): plain files, not stdout or gzip.
    bool patchable() const;
    // Overwrites bytes at `offset` (< offset() - n + 1). Precondition: patchable().
    void patch(uint64_t offset, const void* data, size_t n);
    // Flushes and closes: every byte is on disk (a full disk throws here), not yet under the
    // target's name. For outputs of two files, committed only once both are written.
    // write() after it throws io::Error; a second call does nothing.
    void finish_writing();
    // finish_writing(), then renames into place. Throws io::Error (e.g. disk full). Once only:
    // write() or commit() after it throw io::Error.
    void commit();
    const std::string& name() const { return name_; }
    // True when written in place (stdout, a descriptor, a device or FIFO): no file of its own,
    // so nothing can be put beside it either.
    bool in_place() const { return temp_path_.empty(); }

private:
    ByteSink() = default;
    void flush_buffer();
    void write_raw(const void* data, size_t n);

    std::string name_;       // the target path as given
    std::string target_;     // the file it names, symbolic links followed
    std::string temp_path_;  // empty when written in place (stdout, devices, FIFOs)
    bool owns_fd_ = false;   // written in place to an opened device or FIFO
    int temp_slot_ = -1;     // register_temp_path() slot
    int fd_ = -1;
    bool written_ = false;  // finish_writing() done
    bool committed_ = false;
    struct Gzip;
    std::unique_ptr<Gzip> gz_;
    std::vector<std::byte> buf_;
    uint64_t offset_ = 0;
};

// A temporary file for spills, runs and bodies that are assembled later. Registered so a
// signal handler (install_cleanup_handlers) can unlink it; removed by the destructor.
class TempFile {
public:
    // Creates the file in `dir` (empty: $TMPDIR or /tmp). Throws io::Error.
    explicit TempFile(const std::string& dir = {}, const std::string& stem = "meshstream");
    ~TempFile();
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;

    const std::string& path() const { return path_; }
    int fd() const { return fd_; }
    // Buffered sequential writing; offset() counts bytes written.
    void write(const void* data, size_t n);
    void flush();
    uint64_t size() const { return offset_ + buf_.size(); }
    // Reads n bytes at `offset` (pread), flushing pending writes first. Throws on short read.
    void read_at(uint64_t offset, void* dst, size_t n);
    // The same of what was flushed, without flushing: safe on several threads at once while
    // nothing is written.
    void read_flushed_at(uint64_t offset, void* dst, size_t n) const;

private:
    std::string path_;
    int slot_ = -1;  // register_temp_path() slot
    int fd_ = -1;
    uint64_t offset_ = 0;
    std::vector<std::byte> buf_;
};

// Registers a path to unlink if the process is interrupted; returns a slot for unregister
// (-1 when the table is full or the path too long). Thread-safe.
int register_temp_path(const std::string& path);
void unregister_temp_path(int slot);
// Installs SIGINT/SIGTERM/SIGHUP/SIGPIPE handlers that unlink every registered path, then re-raise,
// and ignores SIGXFSZ so a file-size limit surfaces as a write error (EFBIG).
void install_cleanup_handlers();

// Directory part of a path ("." when there is none).
std::string parent_dir(const std::string& path);

}  // namespace meshstream::io
