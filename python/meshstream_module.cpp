// The compiled half of the Python package `meshstream` (python/meshstream/__init__.py is the
// other): whole meshes as numpy arrays (io::read_indexed, and the registry's writers fed from
// arrays), the chunk stream as numpy views (io::TriangleInput), a streaming Writer, and the
// commands' jobs (tools/jobs.hpp) as calls returning their --json object as a dict.
//
// Keyword arguments are the commands' flags (from_ = --from, draco_qp = --draco-qp): each is
// handed to the command's own option as text, so its checks, conversions and words are the
// command's, and a bad value raises ValueError in them. The work runs without the GIL; the
// progress callable and the Ctrl-C check run with it, from the job's ProgressSink, which
// cancels the job (engine::Cancelled: its output removed) when either raises.
#include "engine/warnings.hpp"
#include "io/error.hpp"
#include "io/format.hpp"
#include "io/read_indexed.hpp"
#include "io/triangle_input.hpp"
#include "tools/common.hpp"
#include "tools/jobs.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace py = pybind11;
using namespace meshstream;

namespace {

// ---- errors -------------------------------------------------------------------------------

py::object g_error;  // meshstream.Error

// Raises the Python exception for a C++ one, as the module's docstring says.
[[noreturn]] void raise_error(const meshstream::Error& e) {
    const std::string text = e.describe(tools::flag_name);
    if (const auto* io_error = dynamic_cast<const io::Error*>(&e)) {
        py::object err = g_error(text);
        err.attr("file") = io_error->file();
        err.attr("line") = io_error->line() ? py::object(py::int_(io_error->line())) : py::object(py::none());
        err.attr("offset") = io_error->byte_offset() != io::Error::kNoOffset
                                 ? py::object(py::int_(io_error->byte_offset()))
                                 : py::object(py::none());
        err.attr("message") = io::render(io_error->raw_message(), tools::flag_name);
        PyErr_SetObject(g_error.ptr(), err.ptr());
        throw py::error_already_set();
    }
    if (dynamic_cast<const io::OptionError*>(&e)) throw py::value_error(text);
    py::object err = g_error(text);
    err.attr("file") = py::none();
    err.attr("line") = py::none();
    err.attr("offset") = py::none();
    err.attr("message") = text;
    PyErr_SetObject(g_error.ptr(), err.ptr());
    throw py::error_already_set();
}

// ---- progress -----------------------------------------------------------------------------

// The job's sink: calls `callable(phase, done, total)` and PyErr_CheckSignals() with the GIL,
// at most every 50 ms (and at each new phase); the first Python exception either raises is
// kept, and cancelled() says true from then on, so the job stops at its next chunk and
// throws engine::Cancelled, which run_job turns back into that exception.
class PythonProgress final : public engine::ProgressSink {
public:
    explicit PythonProgress(py::object callable) : callable_(std::move(callable)) {}
    void phase(std::string label, std::optional<uint64_t> total) override {
        std::lock_guard lock(mutex_);
        label_ = std::move(label);
        total_ = total;
        done_ = 0;
        call(true);
    }
    void update(uint64_t done) override {
        std::lock_guard lock(mutex_);
        done_ = done;
        call(false);
    }
    void update(uint64_t done, uint64_t, std::optional<uint64_t>) override { update(done); }
    void status(const std::string& text) override { phase(text, std::nullopt); }
    bool cancelled() const override { return cancelled_.load(); }
    // Raises the kept Python exception, if any: one the progress raised after the job last
    // looked at cancelled() (the caller holds the GIL).
    void raise_kept() {
        if (error_) rethrow();
    }
    // Rethrows the kept Python exception, or KeyboardInterrupt (the caller holds the GIL).
    [[noreturn]] void rethrow() {
        if (error_) {
            error_->restore();
            error_.reset();
            throw py::error_already_set();
        }
        PyErr_SetNone(PyExc_KeyboardInterrupt);
        throw py::error_already_set();
    }

private:
    void call(bool force) {
        if (cancelled_) return;
        const auto now = std::chrono::steady_clock::now();
        if (!force && now - last_ < std::chrono::milliseconds(50)) return;
        last_ = now;
        py::gil_scoped_acquire gil;
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (!callable_.is_none())
                callable_(label_, done_, total_ ? py::object(py::int_(*total_)) : py::object(py::none()));
        } catch (py::error_already_set& e) {
            error_.emplace(std::move(e));
            cancelled_ = true;
        }
    }

    py::object callable_;
    std::mutex mutex_;
    std::string label_;
    std::optional<uint64_t> total_;
    uint64_t done_ = 0;
    std::chrono::steady_clock::time_point last_{};
    std::atomic<bool> cancelled_{false};
    std::optional<py::error_already_set> error_;
};

// Runs `job` without the GIL, its errors turned into Python's.
template <class Job>
auto run_job(PythonProgress& progress, Job&& job) {
    try {
        auto result = [&] {
            py::gil_scoped_release nogil;
            return job();
        }();
        progress.raise_kept();
        return result;
    } catch (const engine::Cancelled&) {
        progress.rethrow();
    } catch (const tools::UsageError& e) {
        throw py::value_error(e.what());
    } catch (const CLI::Error& e) {
        throw py::value_error(e.what());
    } catch (const meshstream::Error& e) {
        raise_error(e);
    }
}

// ---- keyword arguments as flags -----------------------------------------------------------

// The text a flag takes for a Python value (None: not given).
std::vector<std::string> flag_texts(const std::string& key, const py::handle& value) {
    if (py::isinstance<py::bool_>(value)) return {value.cast<bool>() ? "true" : "false"};
    if (py::isinstance<py::int_>(value) || py::isinstance<py::str>(value)) return {py::str(value).cast<std::string>()};
    if (py::isinstance<py::float_>(value)) return {py::repr(value).cast<std::string>()};
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
        std::vector<std::string> out;
        for (const py::handle item : value) {
            if (!py::isinstance<py::str>(item) && !py::isinstance<py::int_>(item))
                throw py::type_error(key + ": expected text or numbers, found " +
                                     py::str(py::type::of(item).attr("__name__")).cast<std::string>());
            out.push_back(py::str(item).cast<std::string>());
        }
        return out;
    }
    throw py::type_error(key + ": expected a number, text or a list of them, found " +
                         py::str(py::type::of(value).attr("__name__")).cast<std::string>());
}

// Gives each keyword argument to the option of `cmd` it names ("from_" -> --from, "draco_qp"
// -> --draco-qp) as the command line would, which checks and stores it; returns the options
// given. `call` names the function in the TypeError for an unknown keyword.
std::set<const CLI::Option*> apply_flags(CLI::App* cmd, const std::string& call, const py::kwargs& kwargs,
                                         const std::set<std::string>& refused = {}) {
    std::set<const CLI::Option*> given;
    for (const auto& [k, value] : kwargs) {
        const std::string key = k.cast<std::string>();
        std::string name = key;
        while (!name.empty() && name.back() == '_') name.pop_back();
        for (char& c : name)
            if (c == '_') c = '-';
        CLI::Option* option = refused.count(name) ? nullptr : cmd->get_option_no_throw("--" + name);
        if (option == nullptr || name == "help" || name == "help-all" || name == "json")
            throw py::type_error(call + "() got an unexpected keyword argument '" + key + "'");
        if (value.is_none()) continue;
        try {
            for (const std::string& text : flag_texts(key, value)) option->add_result(text);
            option->run_callback();
        } catch (const CLI::Error& e) {
            throw py::value_error(e.what());
        }
        given.insert(option);
    }
    // What the command line refuses at the end of parsing: options that exclude each other.
    for (const CLI::Option* option : given)
        for (const CLI::Option* other : option->get_excludes())
            if (given.count(other))
                throw py::value_error(CLI::ExcludesError(option->get_name(), other->get_name()).what());
    return given;
}

// ---- numpy --------------------------------------------------------------------------------

// A numpy array owning `values` (moved, no copy).
template <class T>
py::array_t<T> owning_array(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
    auto* held = new std::vector<T>(std::move(values));
    py::capsule owner(held, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return py::array_t<T>(shape, held->data(), owner);
}

// A numpy view of the values at `data`, shaped `shape` (C order), kept alive by `base`.
template <class T>
py::object view(const T* data, std::vector<py::ssize_t> shape, py::handle base) {
    return py::array_t<T>(shape, data, base);
}

const char* type_name(io::ScalarType t) {
    switch (t) {
        case io::ScalarType::kInt8: return "int8";
        case io::ScalarType::kUInt8: return "uint8";
        case io::ScalarType::kInt16: return "int16";
        case io::ScalarType::kUInt16: return "uint16";
        case io::ScalarType::kInt32: return "int32";
        case io::ScalarType::kUInt32: return "uint32";
        case io::ScalarType::kFloat32: return "float32";
        case io::ScalarType::kFloat64: return "float64";
    }
    return "float32";
}

io::ScalarType scalar_type(const std::string& name, const std::string& what) {
    for (int t = 0; t <= int(io::ScalarType::kFloat64); ++t)
        if (name == type_name(io::ScalarType(t))) return io::ScalarType(t);
    throw py::value_error(
        what + ": must be one of int8, uint8, int16, uint16, int32, uint32, float32, float64, found '" + name + "'");
}

py::list materials_list(const std::vector<io::Material>& materials) {
    py::list out;
    for (const io::Material& m : materials) {
        py::dict d;
        d["name"] = m.name;
        d["base_color"] = py::make_tuple(m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]);
        if (m.texture) {
            py::dict t;
            t["uri"] = m.texture->uri;
            t["mime_type"] = m.texture->mime_type;
            t["bytes"] = py::bytes(reinterpret_cast<const char*>(m.texture->bytes.data()), m.texture->bytes.size());
            d["texture"] = t;
        } else {
            d["texture"] = py::none();
        }
        out.append(d);
    }
    return out;
}

std::vector<io::Material> materials_of(const py::handle& list) {
    std::vector<io::Material> out;
    if (list.is_none()) return out;
    for (const py::handle item : list) {
        io::Material m;
        m.name = item["name"].cast<std::string>();
        if (item.contains("base_color") && !item["base_color"].is_none()) {
            const auto c = item["base_color"].cast<std::vector<float>>();
            if (c.size() != 4) throw py::value_error("material base_color: expected 4 values (RGBA)");
            for (int k = 0; k < 4; ++k) m.base_color[k] = c[k];
        }
        if (item.contains("texture") && !item["texture"].is_none()) {
            const py::handle t = item["texture"];
            io::Texture texture;
            texture.uri = t["uri"].cast<std::string>();
            if (t.contains("mime_type")) texture.mime_type = t["mime_type"].cast<std::string>();
            if (t.contains("bytes")) {
                const std::string bytes = t["bytes"].cast<std::string>();
                texture.bytes.resize(bytes.size());
                std::memcpy(texture.bytes.data(), bytes.data(), bytes.size());
            }
            m.texture = std::move(texture);
        }
        out.push_back(std::move(m));
    }
    return out;
}

py::dict channels_dict(const io::Channels& c) {
    py::dict d;
    d["normals"] = c.normal;
    if (c.color)
        d["colors"] = py::dict(py::arg("type") = type_name(c.color->type), py::arg("alpha") = c.color->alpha);
    else
        d["colors"] = py::none();
    d["uv_sets"] = c.uv_sets;
    py::dict vs, fs;
    for (const io::ScalarChannel& s : c.vertex_scalars) vs[py::str(s.name)] = type_name(s.type);
    for (const io::ScalarChannel& s : c.face_scalars) fs[py::str(s.name)] = type_name(s.type);
    d["vertex_scalars"] = vs;
    d["face_scalars"] = fs;
    d["materials"] = c.material;
    d["vertex_ids"] = c.vertex_id;
    return d;
}

// ---- reading ------------------------------------------------------------------------------

// The flags of a call that reads (--from, --memory, --tmpdir, --strict, --drop) or writes
// (--to, --gzip-level, --compress, --normals, --draco-*, and --memory, --tmpdir, --strict for
// the writer), from its keyword arguments.
struct FlagsCall {
    CLI::App app;
    tools::ReadFlags read;
    tools::WriteFlags write;
    enum Kind { kRead, kWrite };
    FlagsCall(Kind kind, const std::string& call, const py::kwargs& kwargs) {
        CLI::App* cmd = app.add_subcommand(call);
        tools::add_read_flags(cmd, read);
        if (kind == kRead) {
            tools::add_drop_flag(cmd, read);
            apply_flags(cmd, call, kwargs);
        } else {
            tools::add_write_flags(cmd, write);
            apply_flags(cmd, call, kwargs, {"from", "no-draco", "drop"});
        }
    }
};

py::dict read_mesh(const std::string& path, const py::kwargs& kwargs) {
    FlagsCall call(FlagsCall::kRead, "read", kwargs);
    PythonProgress progress{py::none()};
    io::IndexedFile file =
        run_job(progress, [&] { return io::read_indexed(path, call.read.options(), call.read.from); });
    io::IndexedMesh& mesh = file.mesh;
    const py::ssize_t n = py::ssize_t(mesh.vertex_count()), m = py::ssize_t(mesh.triangle_count());
    py::dict d;
    const io::Channels channels = mesh.channels;
    // The per-vertex values, unpacked from the records channel by channel.
    io::VertexValues values;
    if (!mesh.attributes.empty()) {
        std::vector<uint32_t> all(mesh.vertex_count());
        for (uint32_t v = 0; v < all.size(); ++v) all[v] = v;
        values = mesh.values(all);
        mesh.attributes = {};
    }
    d["vertices"] = owning_array(std::move(mesh.positions), {n, 3});
    d["faces"] = owning_array(std::move(mesh.indices), {m, 3});
    d["normals"] = channels.normal ? py::object(owning_array(std::move(values.normals), {n, 3})) : py::none();
    d["colors"] = channels.color ? py::object(owning_array(std::move(values.colors), {n, 4})) : py::none();
    d["color_type"] = channels.color ? py::object(py::str(type_name(channels.color->type))) : py::none();
    d["color_alpha"] = channels.color ? channels.color->alpha : false;
    py::list uvs;
    for (auto& set : values.uvs) uvs.append(owning_array(std::move(set), {n, 2}));
    d["uvs"] = uvs;
    py::dict scalars, scalar_types;
    for (size_t c = 0; c < channels.vertex_scalars.size(); ++c) {
        scalars[py::str(channels.vertex_scalars[c].name)] = owning_array(std::move(values.scalars[c]), {n});
        scalar_types[py::str(channels.vertex_scalars[c].name)] = type_name(channels.vertex_scalars[c].type);
    }
    d["scalars"] = scalars;
    d["scalar_types"] = scalar_types;
    d["face_materials"] = channels.material ? py::object(owning_array(std::move(mesh.materials), {m})) : py::none();
    d["materials"] = materials_list(file.header.materials);
    d["format"] = std::string(file.format->name);
    d["non_finite_triangles"] = file.non_finite_triangles;
    d["non_finite_attributes"] = file.non_finite_attributes;
    // What the reader changed or left out, and the per-face scalars an IndexedMesh does not hold,
    // in the words and codes of the commands' reports.
    engine::Warnings warnings;
    engine::note_input_changes(file.header, path, warnings);
    std::string face_scalars;
    for (const io::ScalarChannel& s : call.read.options().channels.of(file.header.channels).face_scalars)
        face_scalars += (face_scalars.empty() ? "'" : ", '") + s.name + "'";
    if (!face_scalars.empty())
        warnings.note("channels_dropped", "per-face scalars " + face_scalars +
                                              " left out: read() holds per-vertex channels and the material; "
                                              "chunks() gives them");
    py::list said;
    for (const engine::Warnings::Line& l : warnings.all()) {
        py::dict w;
        w["code"] = l.code, w["text"] = l.text, w["count"] = l.count;
        said.append(w);
    }
    d["warnings"] = said;
    return d;
}

// ---- the chunk stream ---------------------------------------------------------------------

// One chunk of a ChunkReader: views of the reader's chunk, valid until its next one.
struct ChunkView {
    std::shared_ptr<io::TriangleChunk> chunk;
    uint64_t generation = 0;
    std::shared_ptr<uint64_t> current;  // the reader's generation now
    void check() const {
        if (*current != generation)
            throw std::logic_error(
                "meshstream.Chunk: the reader has moved on to the next chunk, which reuses this one's memory; copy "
                "the arrays (numpy.copy) to keep them");
    }
};

// A Chunk property: `get(chunk, triangles, self)` makes its arrays, views kept alive by self
// (a default py::object is None).
template <class Get>
auto chunk_array(Get get) {
    return [get](py::handle self) -> py::object {
        const ChunkView& c = self.cast<const ChunkView&>();
        c.check();
        py::object out = get(static_cast<const io::TriangleChunk&>(*c.chunk), py::ssize_t(c.chunk->size()), self);
        return out ? out : py::none();
    };
}

class ChunkReader {
public:
    ChunkReader(const std::string& path, size_t capacity, const py::kwargs& kwargs)
        : call_(FlagsCall::kRead, "chunks", kwargs), progress_(py::none()) {
        if (capacity == 0) throw py::value_error("capacity: must be at least 1 triangle");
        input_.emplace(run_job(progress_, [&] {
            return io::TriangleInput(io::open_input(path, call_.read.from, call_.read.options()),
                                     io::BadTriangles::kKeep);
        }));
        const io::ReadOptions options = call_.read.options();
        chunk_ = std::make_shared<io::TriangleChunk>(capacity, options.channels.of(input_->header().channels));
    }
    ChunkView next() {
        if (!input_) throw py::stop_iteration();
        ++*generation_;
        const bool more = run_job(progress_, [&] { return input_->next(*chunk_); });
        if (!more) {
            header_ = input_->header();
            input_.reset();
            throw py::stop_iteration();
        }
        return ChunkView{chunk_, *generation_, generation_};
    }
    const io::MeshHeader& header() const { return input_ ? input_->header() : header_; }
    const io::Channels& channels() const { return chunk_->channels(); }

private:
    FlagsCall call_;
    PythonProgress progress_;
    std::optional<io::TriangleInput> input_;
    io::MeshHeader header_;  // once the input is closed
    std::shared_ptr<io::TriangleChunk> chunk_;
    std::shared_ptr<uint64_t> generation_ = std::make_shared<uint64_t>(0);
};

// ---- writing ------------------------------------------------------------------------------

template <class T>
using carray = py::array_t<T, py::array::c_style | py::array::forcecast>;

// A triangle stream's channels from arrays and their types.
struct ArraysIn {
    carray<float> positions;  // t×3×3 (chunks) or n×3 (vertices)
    std::optional<carray<float>> normals, colors;
    std::vector<carray<float>> uvs;
    std::vector<std::pair<std::string, carray<double>>> vertex_scalars, face_scalars;
    std::optional<carray<uint32_t>> materials;
};

void need_shape(const py::array& a, std::vector<py::ssize_t> shape, const std::string& what) {
    bool ok = a.ndim() == py::ssize_t(shape.size());
    for (size_t k = 0; ok && k < shape.size(); ++k) ok = shape[k] < 0 || a.shape(k) == shape[k];
    if (ok) return;
    std::string want, got;
    for (size_t k = 0; k < shape.size(); ++k)
        want += (k ? "×" : "") + (shape[k] < 0 ? std::string("n") : std::to_string(shape[k]));
    for (py::ssize_t k = 0; k < a.ndim(); ++k) got += (k ? "×" : "") + std::to_string(a.shape(k));
    throw py::value_error(what + ": expected an array of shape " + want + ", found " +
                          (got.empty() ? "a scalar" : got));
}

// The Channels the arrays carry.
io::Channels channels_of(const ArraysIn& in, const std::string& color_type, bool color_alpha,
                         const py::dict& scalar_types) {
    io::Channels c;
    c.normal = in.normals.has_value();
    if (in.colors) c.color = io::ColorFormat{scalar_type(color_type, "color_type"), color_alpha};
    if (in.uvs.size() > size_t(io::kMaxUvSets))
        throw py::value_error("uvs: at most " + std::to_string(io::kMaxUvSets) + " texture coordinate sets");
    c.uv_sets = int(in.uvs.size());
    auto type_of = [&](const std::string& name) {
        return scalar_types.contains(name) ? scalar_type(scalar_types[py::str(name)].cast<std::string>(), name)
                                           : io::ScalarType::kFloat32;
    };
    for (const auto& [name, a] : in.vertex_scalars) c.vertex_scalars.push_back({name, type_of(name)});
    for (const auto& [name, a] : in.face_scalars) c.face_scalars.push_back({name, type_of(name)});
    c.material = in.materials.has_value();
    return c;
}

// An output being written: opened at the first chunk, whose channels are the stream's.
class StreamWriter {
public:
    StreamWriter(std::string path, std::vector<io::Material> materials, const py::kwargs& kwargs)
        : path_(std::move(path)),
          materials_(std::move(materials)),
          call_(FlagsCall::kWrite, "Writer", kwargs),
          progress_(py::none()) {
        format_ = run_job(progress_, [&] { return &tools::resolve_output_format(path_, call_.write); });
    }
    // Opens the output for chunks of `channels` (once); returns the channels the writer keeps.
    const io::Channels& open(const io::Channels& channels, std::optional<uint64_t> triangles) {
        if (finished_) throw std::logic_error("meshstream.Writer: written to after it was closed");
        if (output_) {
            if (!(channels == in_channels_))
                throw py::value_error(
                    "Writer.write: every write must carry the same channels as the first one (normals, colors, uvs, "
                    "scalars, materials)");
            return kept_;
        }
        in_channels_ = channels;
        io::WriteOptions options = call_.write.options(call_.read, *format_);
        kept_ = io::writable_channels(*format_, channels, options);
        options.channels = kept_;
        options.materials = materials_;
        options.strict = call_.read.strict;
        options.triangle_count = triangles;
        output_.emplace(
            run_job(progress_, [&] { return io::open_output(path_, format_->name, options, call_.write.gzip_level); }));
        chunk_.emplace(io::TriangleChunk::kDefaultCapacity, kept_);
        return kept_;
    }
    void write(const io::TriangleChunk& chunk) {
        run_job(progress_, [&] {
            output_->write(chunk);
            return 0;
        });
    }
    // A chunk of the kept channels, for at least `capacity` triangles.
    io::TriangleChunk& scratch(size_t capacity = io::TriangleChunk::kDefaultCapacity) {
        if (chunk_->capacity() < capacity) chunk_.emplace(capacity, kept_);
        return *chunk_;
    }
    bool opened() const { return output_.has_value(); }
    // Finishes the output (an output never written to gets no triangles, positions only).
    void close() {
        if (finished_) return;
        if (!output_) open({}, 0);
        finished_ = true;
        run_job(progress_, [&] {
            output_->finish();
            return 0;
        });
        notes_ = output_->writer->notes();
        output_.reset();
    }
    // Drops the output: nothing is left under its name.
    void abandon() {
        finished_ = true;
        output_.reset();
    }
    const std::vector<std::string>& notes() const { return notes_; }
    const io::Format& format() const { return *format_; }

private:
    std::string path_;
    std::vector<io::Material> materials_;
    FlagsCall call_;
    PythonProgress progress_;
    const io::Format* format_ = nullptr;
    io::Channels in_channels_, kept_;
    std::optional<io::Output> output_;
    std::optional<io::TriangleChunk> chunk_;
    bool finished_ = false;
    std::vector<std::string> notes_;
};

// Writes triangles [first, first + count) of `in` into the writer's scratch chunk and on:
// with `faces`, `in` holds vertex arrays indexed by them (the corner's vertex id is its index,
// so an indexed writer keeps the vertices apart as given); without, `in` holds t×3 corners.
void write_triangles(StreamWriter& w, const ArraysIn& in, const uint32_t* faces, size_t triangles,
                     size_t vertex_count) {
    io::TriangleChunk& chunk = w.scratch();
    const io::Channels& kept = chunk.channels();
    const float* pos = in.positions.data();
    std::vector<size_t> scalar_index;  // of each kept vertex scalar in `in`
    for (const io::ScalarChannel& s : kept.vertex_scalars)
        for (size_t k = 0; k < in.vertex_scalars.size(); ++k)
            if (in.vertex_scalars[k].first == s.name) scalar_index.push_back(k);
    std::vector<size_t> face_index;
    for (const io::ScalarChannel& s : kept.face_scalars)
        for (size_t k = 0; k < in.face_scalars.size(); ++k)
            if (in.face_scalars[k].first == s.name) face_index.push_back(k);
    size_t t = 0;
    while (t < triangles) {
        chunk.clear();
        const size_t n = std::min(chunk.capacity(), triangles - t);
        chunk.resize(n);
        for (size_t i = 0; i < n; ++i, ++t) {
            for (int k = 0; k < 3; ++k) {
                // The corner's row in the arrays: a vertex (indexed) or a corner (soup).
                size_t row = 3 * t + size_t(k);
                if (faces) {
                    row = faces[3 * t + size_t(k)];
                    if (row >= vertex_count)
                        throw py::value_error("faces: triangle " + std::to_string(t) + " refers to vertex " +
                                              std::to_string(row) + ", past the " + std::to_string(vertex_count) +
                                              " vertices");
                }
                std::memcpy(&chunk.xyz()[9 * i + 3 * size_t(k)], pos + 3 * row, 3 * sizeof(float));
                if (kept.normal)
                    std::memcpy(chunk.normal_at(i) + 3 * k, in.normals->data() + 3 * row, 3 * sizeof(float));
                if (kept.color) std::memcpy(chunk.color_at(i) + 4 * k, in.colors->data() + 4 * row, 4 * sizeof(float));
                for (int s = 0; s < kept.uv_sets; ++s)
                    std::memcpy(chunk.uv_at(i, s) + 2 * k, in.uvs[size_t(s)].data() + 2 * row, 2 * sizeof(float));
                for (size_t c = 0; c < scalar_index.size(); ++c)
                    chunk.vertex_scalar_at(i, c)[k] = in.vertex_scalars[scalar_index[c]].second.data()[row];
                if (kept.vertex_id) chunk.id_at(i)[k] = row;
            }
            if (kept.material) *chunk.material_at(i) = in.materials->data()[t];
            for (size_t c = 0; c < face_index.size(); ++c)
                *chunk.face_scalar_at(i, c) = in.face_scalars[face_index[c]].second.data()[t];
        }
        w.write(chunk);
    }
}

ArraysIn arrays_in(const py::object& positions, const py::object& normals, const py::object& colors,
                   const py::object& uvs, const py::object& vertex_scalars, const py::object& face_scalars,
                   const py::object& materials) {
    ArraysIn in{carray<float>::ensure(positions), {}, {}, {}, {}, {}, {}};
    if (!in.positions) throw py::type_error("positions: expected an array of numbers");
    if (!normals.is_none()) in.normals = carray<float>::ensure(normals);
    if (!colors.is_none()) in.colors = carray<float>::ensure(colors);
    if (!uvs.is_none()) {
        if (py::isinstance<py::array>(uvs))
            in.uvs.push_back(carray<float>::ensure(uvs));
        else
            for (const py::handle set : uvs) in.uvs.push_back(carray<float>::ensure(set));
    }
    if (!vertex_scalars.is_none())
        for (const auto& [k, v] : vertex_scalars.cast<py::dict>())
            in.vertex_scalars.emplace_back(k.cast<std::string>(), carray<double>::ensure(v));
    if (!face_scalars.is_none())
        for (const auto& [k, v] : face_scalars.cast<py::dict>())
            in.face_scalars.emplace_back(k.cast<std::string>(), carray<double>::ensure(v));
    if (!materials.is_none()) in.materials = carray<uint32_t>::ensure(materials);
    return in;
}

// The arrays' shapes: `rows` per-corner (or per-vertex) rows of `lead` shape, `faces` rows of
// per-triangle values.
void check_shapes(const ArraysIn& in, std::vector<py::ssize_t> lead, py::ssize_t triangles) {
    auto with = [&](py::ssize_t last) {
        std::vector<py::ssize_t> s = lead;
        s.push_back(last);
        return s;
    };
    if (in.normals) need_shape(*in.normals, with(3), "normals");
    if (in.colors) need_shape(*in.colors, with(4), "colors");
    for (const auto& set : in.uvs) need_shape(set, with(2), "uvs");
    for (const auto& [name, a] : in.vertex_scalars) need_shape(a, lead, name);
    for (const auto& [name, a] : in.face_scalars) need_shape(a, {triangles}, name);
    if (in.materials) need_shape(*in.materials, {triangles}, "face_materials");
}

void write_mesh(const std::string& path, const py::object& vertices, const py::object& faces, const py::object& normals,
                const py::object& colors, const std::string& color_type, bool color_alpha, const py::object& uvs,
                const py::object& scalars, const py::dict& scalar_types, const py::object& face_materials,
                const py::object& materials, const py::kwargs& kwargs) {
    ArraysIn in = arrays_in(vertices, normals, colors, uvs, scalars, py::none(), face_materials);
    auto f = carray<uint32_t>::ensure(faces);
    if (!f) throw py::type_error("faces: expected an array of vertex indices");
    need_shape(in.positions, {-1, 3}, "vertices");
    need_shape(f, {-1, 3}, "faces");
    const py::ssize_t n = in.positions.shape(0), m = f.shape(0);
    check_shapes(in, {n}, m);
    StreamWriter w(path, materials_of(materials), kwargs);
    io::Channels channels = channels_of(in, color_type, color_alpha, scalar_types);
    channels.vertex_id = true;
    w.open(channels, uint64_t(m));
    try {
        write_triangles(w, in, f.data(), size_t(m), size_t(n));
        w.close();
    } catch (...) {
        w.abandon();
        throw;
    }
}

// `chunk`'s triangles in `out`, which has a subset of its channels (those a writer keeps).
const io::TriangleChunk& narrowed(const io::TriangleChunk& chunk, io::TriangleChunk& out) {
    const io::Channels& from = chunk.channels();
    const io::Channels& to = out.channels();
    auto index_of = [](const std::vector<io::ScalarChannel>& list, const std::string& name) {
        for (size_t k = 0; k < list.size(); ++k)
            if (list[k].name == name) return k;
        return list.size();
    };
    out.clear();
    out.resize(chunk.size());
    for (size_t i = 0; i < chunk.size(); ++i) {
        std::memcpy(&out.xyz()[9 * i], &chunk.xyz()[9 * i], 9 * sizeof(float));
        if (to.normal) std::memcpy(out.normal_at(i), chunk.normal_at(i), 9 * sizeof(float));
        if (to.color) std::memcpy(out.color_at(i), chunk.color_at(i), 12 * sizeof(float));
        for (int s = 0; s < to.uv_sets; ++s) std::memcpy(out.uv_at(i, s), chunk.uv_at(i, s), 6 * sizeof(float));
        for (size_t c = 0; c < to.vertex_scalars.size(); ++c)
            std::memcpy(out.vertex_scalar_at(i, c),
                        chunk.vertex_scalar_at(i, index_of(from.vertex_scalars, to.vertex_scalars[c].name)),
                        3 * sizeof(double));
        if (to.vertex_id) std::memcpy(out.id_at(i), chunk.id_at(i), 3 * sizeof(uint64_t));
        if (to.material) *out.material_at(i) = *chunk.material_at(i);
        for (size_t c = 0; c < to.face_scalars.size(); ++c)
            *out.face_scalar_at(i, c) = *chunk.face_scalar_at(i, index_of(from.face_scalars, to.face_scalars[c].name));
    }
    return out;
}

// ---- jobs ---------------------------------------------------------------------------------

// A path given as str or os.PathLike.
std::string path_of(const py::object& path) {
    return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

py::object to_python(const nlohmann::ordered_json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

template <class Options, class Register, class Job>
py::object command_call(const std::string& name, Options& opt, Register&& register_options, Job&& job,
                        const py::object& progress, const py::kwargs& kwargs,
                        const std::set<std::string>& refused = {}) {
    CLI::App app;
    CLI::App* cmd = register_options(app, opt);
    const std::set<const CLI::Option*> given = apply_flags(cmd, name, kwargs, refused);
    opt.json = true;  // the report is returned, no text printed
    if constexpr (requires { opt.threads_given; }) {
        const CLI::Option* threads = cmd->get_option_no_throw("--threads");
        opt.threads_given = threads && given.count(threads);
    }
    PythonProgress sink(progress);
    const nlohmann::ordered_json report = run_job(sink, [&] { return job(opt, &sink); });
    return to_python(report);
}

// meshstream.<name>(src, dst, *, progress=None, **flags): a job that reads src and writes dst.
template <class Options, class Register, class Job>
void def_file_job(py::module_& m, const char* name, Register register_options, Job job,
                  std::set<std::string> refused = {}) {
    m.def(
        name,
        [name, register_options, job, refused](const py::object& src, const py::object& dst, const py::object& progress,
                                               const py::kwargs& kwargs) {
            Options opt;
            opt.input = path_of(src), opt.output = path_of(dst);
            return command_call(name, opt, register_options, job, progress, kwargs, refused);
        },
        py::arg("src"), py::arg("dst"), py::kw_only(), py::arg("progress") = py::none());
}

}  // namespace

PYBIND11_MODULE(_meshstream, m) {
    m.doc() = "meshstream's readers, writers and jobs (see the meshstream package)";
    tools::global().silent = true;  // warnings are returned in the reports

    g_error = py::reinterpret_borrow<py::object>(PyErr_NewExceptionWithDoc(
        "meshstream.Error",
        "A file that cannot be read or written, or bad input in it: .file, .line (1-based) and .offset "
        "(bytes) say where, when known (None otherwise); .message is the text without the position.",
        PyExc_Exception, nullptr));
    m.attr("Error") = g_error;

    m.def("_read", &read_mesh, py::arg("path"));
    m.def("_write", &write_mesh, py::arg("path"), py::arg("vertices"), py::arg("faces"), py::arg("normals"),
          py::arg("colors"), py::arg("color_type"), py::arg("color_alpha"), py::arg("uvs"), py::arg("scalars"),
          py::arg("scalar_types"), py::arg("face_materials"), py::arg("materials"));

    using Chunk = io::TriangleChunk;
    py::class_<ChunkView>(m, "Chunk", "One chunk of a stream: views valid until the reader's next chunk")
        .def("__len__", [](const ChunkView& c) { return c.chunk->size(); })
        .def_property_readonly("positions", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                                   return view(k.xyz().data(), {t, 3, 3}, self);
                               }))
        .def_property_readonly(
            "normals", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                return k.channels().normal ? view(k.normals().data(), {t, 3, 3}, self) : py::object();
            }))
        .def_property_readonly("colors", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                                   return k.channels().color ? view(k.colors().data(), {t, 3, 4}, self) : py::object();
                               }))
        .def_property_readonly("uvs", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                                   py::list out;
                                   for (int s = 0; s < k.channels().uv_sets; ++s)
                                       out.append(view(k.uv_at(0, s), {t, 3, 2}, self));
                                   return py::object(out);
                               }))
        .def_property_readonly("vertex_scalars", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                                   py::dict out;
                                   const auto& list = k.channels().vertex_scalars;
                                   for (size_t c = 0; c < list.size(); ++c)
                                       out[py::str(list[c].name)] = view(k.vertex_scalar_at(0, c), {t, 3}, self);
                                   return py::object(out);
                               }))
        .def_property_readonly("face_scalars", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                                   py::dict out;
                                   const auto& list = k.channels().face_scalars;
                                   for (size_t c = 0; c < list.size(); ++c)
                                       out[py::str(list[c].name)] = view(k.face_scalar_at(0, c), {t}, self);
                                   return py::object(out);
                               }))
        .def_property_readonly("materials", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                                   return k.channels().material ? view(k.materials().data(), {t}, self) : py::object();
                               }))
        .def_property_readonly(
            "vertex_ids", chunk_array([](const Chunk& k, py::ssize_t t, py::handle self) {
                return k.channels().vertex_id ? view(k.vertex_ids().data(), {t, 3}, self) : py::object();
            }));

    py::class_<ChunkReader>(m, "ChunkReader", "The chunks of a mesh file, one at a time (meshstream.chunks)")
        .def(py::init<const std::string&, size_t, const py::kwargs&>(), py::arg("path"),
             py::arg("capacity") = io::TriangleChunk::kDefaultCapacity)
        .def("__iter__", [](py::handle self) { return self; })
        .def("__next__", &ChunkReader::next)
        .def_property_readonly("channels", [](const ChunkReader& r) { return channels_dict(r.channels()); })
        .def_property_readonly("materials", [](const ChunkReader& r) { return materials_list(r.header().materials); })
        .def_property_readonly("triangle_count", [](const ChunkReader& r) { return r.header().triangle_count; })
        .def_property_readonly("sorted_axis", [](const ChunkReader& r) { return r.header().sorted_axis; });

    py::class_<StreamWriter>(m, "_Writer")
        .def(py::init([](const std::string& path, const py::object& materials, const py::kwargs& kwargs) {
                 return std::make_unique<StreamWriter>(path, materials_of(materials), kwargs);
             }),
             py::arg("path"), py::arg("materials") = py::none())
        .def("write_chunk",
             [](StreamWriter& w, const ChunkView& c) {
                 c.check();
                 const io::TriangleChunk& chunk = *c.chunk;
                 const io::Channels kept = w.open(chunk.channels(), std::nullopt);
                 if (kept == chunk.channels()) return w.write(chunk);
                 w.write(narrowed(chunk, w.scratch(chunk.size())));
             })
        .def(
            "write_arrays",
            [](StreamWriter& w, const py::object& positions, const py::object& normals, const py::object& colors,
               const std::string& color_type, bool color_alpha, const py::object& uvs, const py::object& vertex_scalars,
               const py::dict& scalar_types, const py::object& face_scalars, const py::object& materials) {
                ArraysIn in = arrays_in(positions, normals, colors, uvs, vertex_scalars, face_scalars, materials);
                need_shape(in.positions, {-1, 3, 3}, "positions");
                const py::ssize_t t = in.positions.shape(0);
                check_shapes(in, {t, 3}, t);
                w.open(channels_of(in, color_type, color_alpha, scalar_types), std::nullopt);
                write_triangles(w, in, nullptr, size_t(t), 0);
            })
        .def("close", &StreamWriter::close)
        .def("abandon", &StreamWriter::abandon)
        .def_property_readonly("notes", &StreamWriter::notes);

    def_file_job<tools::ConvertOptions>(m, "convert", tools::convert_command,
                                        [](auto& o, auto* sink) { return tools::convert_job(o, sink); });
    def_file_job<tools::SortOptions>(m, "sort", tools::sort_command,
                                     [](auto& o, auto* sink) { return tools::sort_job(o, sink); }, {"stats"});
    def_file_job<tools::DecimateOptions>(
        m, "decimate", [](CLI::App& app, tools::DecimateOptions& o) { return tools::decimate_command(app, o); },
        [](auto& o, auto* sink) { return tools::decimate_job(o, nullptr, sink); });
#if MESHSTREAM_WITH_GLTF
    def_file_job<tools::TilesOptions>(m, "tiles", tools::tiles_command,
                                      [](auto& o, auto* sink) { return tools::tiles_job(o, sink); });
#endif
    m.def(
        "info",
        [](const py::object& path, const py::object& progress, const py::kwargs& kwargs) {
            tools::InfoOptions opt;
            opt.input = path_of(path);
            return command_call(
                "info", opt, tools::info_command, [](auto& o, auto* s) { return tools::info_job(o, s); }, progress,
                kwargs);
        },
        py::arg("path"), py::kw_only(), py::arg("progress") = py::none());
    m.def(
        "compare",
        [](const py::object& a, const py::object& b, const py::object& progress, const py::kwargs& kwargs) {
            tools::CompareCliOptions opt;
            opt.a = path_of(a), opt.b = path_of(b);
            return command_call(
                "compare", opt, tools::compare_command, [](auto& o, auto* s) { return tools::compare_job(o, s); },
                progress, kwargs);
        },
        py::arg("a"), py::arg("b"), py::kw_only(), py::arg("progress") = py::none());
}
