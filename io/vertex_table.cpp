// The spillable vertex table: memory blocks, then a temp file or the input file read through
// a page cache of its own (see vertex_table.hpp).
#include "io/vertex_table.hpp"

#include "io/error.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <new>

namespace meshstream::io {
namespace {

constexpr uint64_t kNoPage = ~uint64_t{0};
constexpr size_t kTailBytes = size_t{1} << 20;

}  // namespace

VertexTable::VertexTable(uint64_t budget_bytes, std::string tmpdir, size_t attribute_bytes)
    : budget_bytes_(budget_bytes), tmpdir_(std::move(tmpdir)), attribute_bytes_(attribute_bytes) {
    stride_ = 12 + attribute_bytes;  // xyz, then the corner record
}

std::unique_ptr<VertexTable> VertexTable::of_input_file(const std::string& path, uint64_t offset, uint64_t count,
                                                        size_t stride, const size_t (&xyz_offsets)[3],
                                                        uint64_t budget_bytes) {
    std::unique_ptr<VertexTable> t(new VertexTable());
    t->storage_ = Storage::kInputFile;
    t->budget_bytes_ = budget_bytes;
    t->stride_ = stride;
    t->size_ = count;
    t->file_records_ = count;
    t->file_offset_ = offset;
    t->input_path_ = path;
    std::copy(std::begin(xyz_offsets), std::end(xyz_offsets), t->xyz_offsets_);
    if (count == 0) return t;
    t->input_fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (t->input_fd_ < 0)
        throw Error(path, "cannot open to read the vertex block: " + std::string(std::strerror(errno)));
    t->start_cache(count * stride);
    return t;
}

std::unique_ptr<VertexTable> VertexTable::split() {
    std::unique_ptr<VertexTable> t(new VertexTable());
    t->records_ = records_;
    t->storage_ = storage_;
    t->attribute_bytes_ = attribute_bytes_;
    t->size_ = size_;
    t->stride_ = stride_;
    std::copy(std::begin(xyz_offsets_), std::end(xyz_offsets_), t->xyz_offsets_);
    t->file_offset_ = file_offset_;
    t->file_records_ = file_records_;
    if (storage_ != Storage::kMemory && file_records_ > 0) {
        budget_bytes_ /= 2;
        t->budget_bytes_ = budget_bytes_;
        pages_.reset();  // the old cache goes before the new ones are mapped
        start_cache(file_records_ * stride_);
        t->start_cache(file_records_ * stride_);
    }
    return t;
}

VertexTable::~VertexTable() {
    if (input_fd_ >= 0) ::close(input_fd_);
}

void VertexTable::append(const float* xyz, const std::byte* attributes) {
    if (record_.size() != stride_) record_.resize(stride_);
    std::byte* rec = record_.data();
    std::memcpy(rec, xyz, 12);
    if (attribute_bytes_ > 0) std::memcpy(rec + 12, attributes, attribute_bytes_);
    if (storage_ == Storage::kMemory) {
        if ((size_ + 1) * stride_ > budget_bytes_) {
            spill();
        } else {
            size_t in_block = static_cast<size_t>(size_ & ((uint64_t{1} << kBlockRecordsLog2) - 1));
            if (in_block == 0) blocks_.push_back(std::make_unique<std::byte[]>(stride_ << kBlockRecordsLog2));
            std::memcpy(blocks_.back().get() + in_block * stride_, rec, stride_);
            ++size_;
            return;
        }
    }
    // kTempFile: append to the tail, flushing it to the file when full.
    if (tail_.size() + stride_ > kTailBytes) flush_tail();
    tail_.insert(tail_.end(), rec, rec + stride_);
    ++size_;
}

void VertexTable::set_budget(uint64_t budget_bytes) {
    budget_bytes_ = budget_bytes;
    if (storage_ == Storage::kMemory) {
        if (size_ * stride_ > budget_bytes_) spill();
    } else if (storage_ == Storage::kTempFile) {
        pages_.reset();             // the old cache goes before the new one is mapped
        start_cache(~uint64_t{0});  // as spill() sizes it, for the new budget
    }
}

void VertexTable::spill() {
    temp_ = std::make_unique<TempFile>(tmpdir_, "meshstream-vertices");
    for (uint64_t done = 0; done < size_;) {
        size_t n = static_cast<size_t>(std::min<uint64_t>(size_ - done, uint64_t{1} << kBlockRecordsLog2));
        temp_->write(blocks_[done >> kBlockRecordsLog2].get(), n * stride_);
        done += n;
    }
    temp_->flush();
    std::vector<std::unique_ptr<std::byte[]>>().swap(blocks_);
    storage_ = Storage::kTempFile;
    tail_.reserve(kTailBytes);
    file_records_ = size_;
    start_cache(~uint64_t{0});  // the table grows: a cache as large as the budget
}

void VertexTable::flush_tail() {
    if (tail_.empty()) return;
    // The page holding the file's current end may be cached short: it is about to grow.
    const uint64_t end = file_offset_ + file_records_ * stride_;
    if (end % kPageBytes != 0) {
        const uint64_t page = end / kPageBytes - file_offset_ / kPageBytes;
        uint64_t& tag = page_tags_[static_cast<size_t>(page % page_tags_.size())];
        if (tag == page) tag = kNoPage;
    }
    temp_->write(tail_.data(), tail_.size());
    temp_->flush();
    file_records_ += tail_.size() / stride_;
    tail_.clear();
}

void VertexTable::start_cache(uint64_t table_bytes) {
    // Slots for the whole table when it fits the budget (no two pages then share a slot),
    // else as many as the budget holds with their tags; at least 16.
    const uint64_t pages = std::min(table_bytes / kPageBytes + 2,
                                    std::max<uint64_t>(budget_bytes_ / (kPageBytes + sizeof(uint64_t)), 16));
    const size_t bytes = static_cast<size_t>(pages * kPageBytes);
    void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);  // resident when used
    if (p == MAP_FAILED) throw std::bad_alloc();
    pages_ = std::unique_ptr<std::byte, Unmap>(static_cast<std::byte*>(p), Unmap{bytes});
    page_tags_.assign(static_cast<size_t>(pages), kNoPage);
}

void VertexTable::Unmap::operator()(std::byte* p) const { ::munmap(p, bytes); }

void VertexTable::read_file(uint64_t offset, void* dst, size_t n) {
    const VertexTable& owner = *records_;
    const int fd = storage_ == Storage::kInputFile ? owner.input_fd_ : owner.temp_->fd();
    auto* p = static_cast<char*>(dst);
    while (n > 0) {
        const ssize_t got = ::pread(fd, p, n, static_cast<off_t>(offset));
        if (got < 0 && errno == EINTR) continue;
        const std::string& path = storage_ == Storage::kInputFile ? owner.input_path_ : owner.temp_->path();
        if (got < 0) throw Error(path, offset, 0, "cannot read the vertex table: " + std::string(std::strerror(errno)));
        if (got == 0) throw Error(path, offset, 0, "the vertex table ends early (was the file changed while read?)");
        p += got;
        n -= static_cast<size_t>(got);
        offset += static_cast<uint64_t>(got);
    }
}

const std::byte* VertexTable::cached_page(uint64_t page) {
    const size_t slot = static_cast<size_t>(page % page_tags_.size());
    std::byte* data = pages_.get() + slot * kPageBytes;
    if (page_tags_[slot] != page) {
        // Only the part holding records: the file may end, or go on with faces, within it.
        const uint64_t first = file_offset_ / kPageBytes * kPageBytes;
        const uint64_t begin = std::max(first + page * kPageBytes, file_offset_);
        const uint64_t end = std::min(first + (page + 1) * kPageBytes, file_offset_ + file_records_ * stride_);
        read_file(begin, data + (begin - first - page * kPageBytes), static_cast<size_t>(end - begin));
        page_tags_[slot] = page;
    }
    return data;
}

void VertexTable::get(uint64_t i, float* xyz, std::byte* attributes) {
    const std::byte* rec = nullptr;  // the record, when it is in memory
    uint64_t at = 0;                 // else where it starts, from the start of cached page 0
    if (storage_ == Storage::kMemory) {
        rec = records_->blocks_[i >> kBlockRecordsLog2].get() +
              (i & ((uint64_t{1} << kBlockRecordsLog2) - 1)) * stride_;
    } else if (i >= file_records_) {
        rec = records_->tail_.data() + (i - file_records_) * stride_;
    } else {
        at = file_offset_ % kPageBytes + i * stride_;
        // Most records lie within one cached page: found once for all their fields.
        if (at / kPageBytes == (at + stride_ - 1) / kPageBytes) rec = cached_page(at / kPageBytes) + at % kPageBytes;
    }
    // Copies n bytes of the record from `offset` on; from a file, out of the one or two cached
    // pages they span.
    auto field = [&](size_t offset, size_t n, void* dst) {
        if (rec != nullptr) {
            std::memcpy(dst, rec + offset, n);
            return;
        }
        for (size_t done = 0; done < n;) {
            const uint64_t pos = at + offset + done;
            const size_t in_page = static_cast<size_t>(pos % kPageBytes);
            const size_t take = std::min(n - done, kPageBytes - in_page);
            std::memcpy(static_cast<std::byte*>(dst) + done, cached_page(pos / kPageBytes) + in_page, take);
            done += take;
        }
    };
    for (int a = 0; a < 3; ++a) field(xyz_offsets_[a], 4, &xyz[a]);
    if (attributes && attribute_bytes_ > 0) field(12, attribute_bytes_, attributes);
}

void VertexTable::positions(uint64_t first, uint64_t count, float* xyz) {
    const uint64_t end = first + count;
    if (storage_ != Storage::kMemory && first < file_records_) {
        constexpr size_t kReadBytes = size_t{1} << 20;
        const uint64_t per_read = std::max<uint64_t>(1, kReadBytes / stride_);
        std::vector<std::byte> buffer(static_cast<size_t>(std::min(per_read, file_records_ - first) * stride_));
        while (first < std::min(end, file_records_)) {
            const uint64_t n = std::min({per_read, end - first, file_records_ - first});
            read_file(file_offset_ + first * stride_, buffer.data(), static_cast<size_t>(n * stride_));
            for (uint64_t r = 0; r < n; ++r, xyz += 3)
                for (int a = 0; a < 3; ++a) std::memcpy(&xyz[a], &buffer[r * stride_ + xyz_offsets_[a]], 4);
            first += n;
        }
    }
    for (; first < end; ++first, xyz += 3) get(first, xyz, nullptr);  // in memory, or the temp file's tail
}

bool emit_polygon(VertexTable& table, const CornerLayout* layout, const std::vector<uint64_t>& polygon,
                  PolygonScratch& scratch, size_t* next, TriangleChunk& chunk) {
    const size_t n = polygon.size();
    if (*next + 2 >= n) return true;  // done, or fewer than 3 corners
    if (chunk.full()) return false;
    // The corner records are unpacked only when both the table has them and the chunk wants them.
    const size_t rec = layout != nullptr ? layout->bytes() : 0;
    if (scratch.record.size() < rec) scratch.record.resize(rec);
    if (n == 3) {  // most faces: straight into the chunk
        size_t i = chunk.size();
        float* xyz = chunk.push_slot();
        uint64_t* ids = chunk.id_at(i);
        for (int k = 0; k < 3; ++k) {
            table.get(polygon[k], xyz + 3 * k, rec > 0 ? scratch.record.data() : nullptr);
            if (rec > 0) layout->unpack(scratch.record.data(), chunk, i, k);
            if (ids) ids[k] = polygon[k];
        }
        *next = 1;
        return true;
    }
    if (*next == 0) {
        // Each corner is read once, then copied into its triangles.
        scratch.xyz.resize(3 * n);
        scratch.records.resize(rec * n);
        for (size_t k = 0; k < n; ++k)
            table.get(polygon[k], &scratch.xyz[3 * k], rec > 0 ? &scratch.records[rec * k] : nullptr);
        scratch.triangles.clear();
        triangulate_polygon(scratch.xyz, scratch.triangulate, scratch.triangles);
    }
    for (; *next + 2 < n; ++*next) {
        if (chunk.full()) return false;
        size_t i = chunk.size();
        float* xyz = chunk.push_slot();
        uint64_t* ids = chunk.id_at(i);
        for (int k = 0; k < 3; ++k) {
            const uint32_t corner = scratch.triangles[3 * *next + k];
            std::memcpy(xyz + 3 * k, &scratch.xyz[3 * corner], 3 * sizeof(float));
            if (rec > 0) layout->unpack(&scratch.records[rec * corner], chunk, i, k);
            if (ids) ids[k] = polygon[corner];
        }
    }
    return true;
}

}  // namespace meshstream::io
