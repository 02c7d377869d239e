# The Python package against the command and the corpus: whole meshes and their channels,
# round trips through the writers, the chunk stream and Writer, every job's report against the
# command's --json, its output byte for byte, errors with their positions, bad arguments in
# the command's words, progress, cancellation, and the GIL released while a job runs.
import filecmp
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import meshstream
from conftest import BINARY, fixture, run_json, without_timings


# ---- whole meshes ----------------------------------------------------------------------------

def test_read_cube_with_normals_and_uvs_keeps_the_seams_apart():
    mesh = meshstream.read(fixture("ply", "cube_uv.ply"))
    # 6 quads = 12 triangles; every face has its own normal and uvs, so 4 vertices a face.
    assert mesh.vertices.shape == (24, 3) and mesh.vertices.dtype == np.float32
    assert mesh.faces.shape == (12, 3) and mesh.faces.dtype == np.uint32
    assert mesh.normals.shape == (24, 3) and mesh.normals.dtype == np.float32
    assert len(mesh.uvs) == 1 and mesh.uvs[0].shape == (24, 2) and mesh.uvs[0].dtype == np.float32
    assert mesh.colors is None and mesh.face_materials is None and mesh.scalars == {}
    assert mesh.format == "ply"
    # The bounding box info measures, and every normal a unit axis.
    box = run_json("info", fixture("ply", "cube_uv.ply"))
    assert mesh.vertices.min(axis=0).tolist() == box["bbox_min"]
    assert mesh.vertices.max(axis=0).tolist() == box["bbox_max"]
    assert np.all(np.abs(mesh.normals).sum(axis=1) == 1)


def test_read_says_what_it_left_out(tmp_path):
    # A face of two vertices (skipped by the reader) and a per-face scalar (not in a Mesh).
    path = tmp_path / "label.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                    "property int label\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 7\n2 0 1 8\n")
    mesh = meshstream.read(path)
    assert len(mesh.faces) == 1
    said = {w["code"]: w for w in mesh.warnings}
    assert said["reader_warning"]["count"] == 1 and "fewer than 3" in said["reader_warning"]["text"]
    assert "'label'" in said["channels_dropped"]["text"] and "chunks()" in said["channels_dropped"]["text"]
    assert meshstream.read(fixture("ply", "cube_uv.ply")).warnings == []
    assert meshstream.read(path, drop="extra").warnings == [said["reader_warning"]]


def test_read_counts_match_info():
    for name in (("ply", "cactus_vcolor.binary_le.ply"), ("obj", "WusonOBJ.obj"), ("cube.bin.stl",)):
        mesh = meshstream.read(fixture(*name))
        assert len(mesh.faces) == run_json("info", fixture(*name))["triangles"], name


def test_read_colours_with_their_type():
    mesh = meshstream.read(fixture("ply", "cactus_vcolor.binary_le.ply"))
    assert mesh.colors.dtype == np.float32 and mesh.colors.shape == (len(mesh.vertices), 4)
    assert mesh.color_type == "uint8"
    # uint8 colours travel as value / 255: scaled back they are whole numbers.
    assert np.array_equal(mesh.colors * 255, np.round(mesh.colors * 255))


def test_read_materials_and_their_table():
    mesh = meshstream.read(fixture("obj", "cube_usemtl.obj"))
    assert mesh.face_materials.dtype == np.uint32 and len(mesh.face_materials) == len(mesh.faces)
    names = [m["name"] for m in mesh.materials]
    assert "mtl" in names and "mtl3" in names
    mtl = mesh.materials[names.index("mtl")]
    assert mtl["base_color"] == pytest.approx((0.8, 0.125, 0.1, 1.0))
    assert mtl["texture"]["uri"] == "checker.png" and len(mtl["texture"]["bytes"]) > 0
    assert set(mesh.face_materials.tolist()) <= set(range(len(mesh.materials)))


def test_read_named_scalars(tmp_path):
    verts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    faces = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    mesh = meshstream.Mesh(verts, faces, scalars={"intensity": [0.5, 1.5, 2.5, 3.5]},
                           scalar_types={"intensity": "float32"})
    meshstream.write(tmp_path / "s.ply", mesh)
    back = meshstream.read(tmp_path / "s.ply")
    assert back.scalar_types == {"intensity": "float32"}
    assert back.scalars["intensity"].dtype == np.float64
    assert np.array_equal(back.scalars["intensity"], [0.5, 1.5, 2.5, 3.5])


def assert_same_mesh(a, b):
    assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(a.faces, b.faces)
    for name in ("normals", "colors", "face_materials"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert np.array_equal(x, y), name
    assert len(a.uvs) == len(b.uvs) and all(np.array_equal(x, y) for x, y in zip(a.uvs, b.uvs))


@pytest.mark.parametrize("name,out", [
    (("ply", "cactus_vcolor.binary_le.ply"), "out.ply"),
    (("ply", "cube_uv.ply"), "out.ply"),
    (("obj", "cube_usemtl.obj"), "out.obj"),
    (("obj", "WusonOBJ.obj"), "out.ply"),
    (("cube.bin.stl",), "out.stl"),
])
def test_read_write_read_gives_equal_arrays(tmp_path, name, out):
    mesh = meshstream.read(fixture(*name))
    meshstream.write(tmp_path / out, mesh)
    back = meshstream.read(tmp_path / out)
    if out.endswith(".stl"):  # STL keeps positions only: the same triangles, welded again
        assert np.array_equal(mesh.vertices[mesh.faces], back.vertices[back.faces])
        return
    assert_same_mesh(mesh, back)
    if mesh.materials:
        assert [m["name"] for m in back.materials] == [m["name"] for m in mesh.materials]


def test_write_arrays_and_options(tmp_path):
    verts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
    faces = np.array([[0, 1, 2], [2, 1, 3]], np.uint32)
    meshstream.write(tmp_path / "a.ply.gz", verts, faces, gzip_level=9)
    back = meshstream.read(tmp_path / "a.ply.gz")
    assert np.array_equal(back.vertices, verts) and np.array_equal(back.faces, faces)
    meshstream.write(tmp_path / "a.drc", verts, faces, draco_qp=20)
    assert len(meshstream.read(tmp_path / "a.drc").faces) == 2
    meshstream.write(tmp_path / "a.txt", verts, faces, to="obj")
    assert meshstream.info(tmp_path / "a.txt", from_="obj")["format"] == "obj"


def test_write_refuses_bad_arrays_and_leaves_nothing(tmp_path):
    verts = np.zeros((3, 3), np.float32)
    with pytest.raises(ValueError, match=r"faces: triangle 0 refers to vertex 7, past the 3 vertices"):
        meshstream.write(tmp_path / "bad.ply", verts, np.array([[0, 1, 7]], np.uint32))
    assert not os.path.exists(tmp_path / "bad.ply")
    with pytest.raises(ValueError, match=r"vertices: expected an array of shape n×3, found 3×2"):
        meshstream.write(tmp_path / "bad.ply", np.zeros((3, 2)), np.array([[0, 1, 2]]))


# ---- chunks and Writer -----------------------------------------------------------------------

def test_chunks_cover_the_file_as_views(generated):
    reader = meshstream.chunks(generated, capacity=50000)
    triangles = run_json("info", generated)["triangles"]
    assert reader.triangle_count == triangles  # binary STL states its count
    sizes, first = [], None
    for chunk in reader:
        assert chunk.positions.dtype == np.float32 and chunk.positions.shape == (len(chunk), 3, 3)
        assert not chunk.positions.flags.owndata  # a view of the reader's chunk
        if first is None:
            first = chunk.positions.copy()
            kept = chunk
        sizes.append(len(chunk))
    assert sum(sizes) == triangles
    assert max(sizes) == 50000
    whole = meshstream.read(generated)
    assert np.array_equal(first, whole.vertices[whole.faces][:50000])
    with pytest.raises(RuntimeError, match="moved on to the next chunk"):
        kept.positions


def test_chunk_channels_have_their_dtypes():
    reader = meshstream.chunks(fixture("ply", "cube_uv.ply"))
    assert reader.channels["normals"] and reader.channels["uv_sets"] == 1
    chunk = next(iter(reader))
    assert chunk.normals.shape == (12, 3, 3) and chunk.normals.dtype == np.float32
    assert len(chunk.uvs) == 1 and chunk.uvs[0].shape == (12, 3, 2)
    assert chunk.colors is None and chunk.materials is None
    reader = meshstream.chunks(fixture("obj", "cube_usemtl.obj"))
    chunk = next(iter(reader))
    assert chunk.materials.dtype == np.uint32 and chunk.materials.shape == (len(chunk),)


def test_writer_takes_chunks_and_arrays(tmp_path, coloured):
    reader = meshstream.chunks(coloured, capacity=7000)
    with meshstream.Writer(tmp_path / "copy.ply") as w:
        for chunk in reader:
            w.write(chunk)
    # The same triangles and colours as convert writes.
    subprocess.run([BINARY, "-q", "convert", coloured, str(tmp_path / "cmd.ply")], check=True)
    a, b = meshstream.read(tmp_path / "copy.ply"), meshstream.read(tmp_path / "cmd.ply")
    assert_same_mesh(a, b)
    # Arrays of corners, in pieces.
    mesh = meshstream.read(coloured)
    corners = mesh.vertices[mesh.faces]
    colours = mesh.colors[mesh.faces]
    with meshstream.Writer(tmp_path / "arrays.ply") as w:
        for start in range(0, len(corners), 25000):
            w.write(corners[start:start + 25000], colors=colours[start:start + 25000])
    c = meshstream.read(tmp_path / "arrays.ply")
    assert np.array_equal(c.vertices[c.faces], corners) and np.array_equal(c.colors[c.faces], colours)


def test_writer_leaves_nothing_when_the_block_fails(tmp_path):
    with pytest.raises(ZeroDivisionError):
        with meshstream.Writer(tmp_path / "half.stl") as w:
            w.write(np.zeros((4, 3, 3), np.float32))
            1 / 0
    assert not os.path.exists(tmp_path / "half.stl")
    with pytest.raises(ValueError, match="same channels"):
        with meshstream.Writer(tmp_path / "mixed.ply") as w:
            w.write(np.zeros((1, 3, 3), np.float32))
            w.write(np.zeros((1, 3, 3), np.float32), normals=np.zeros((1, 3, 3), np.float32))
    assert not os.path.exists(tmp_path / "mixed.ply")


# ---- jobs: the command's reports and outputs ---------------------------------------------------

def test_decimate_matches_the_command_byte_for_byte(tmp_path, generated):
    py_out, cmd_out = tmp_path / "py.ply", tmp_path / "cmd.ply"
    report = meshstream.decimate(generated, py_out, ratio=0.1, seed=3, threads=2, buffer=20000)
    command = run_json("decimate", generated, str(cmd_out), "--ratio", "0.1", "--seed", "3", "--threads", "2",
                       "--buffer", "20000")
    assert filecmp.cmp(py_out, cmd_out, shallow=False)
    command["outputs"][0]["path"] = str(py_out)
    assert without_timings(report) == without_timings(command)
    assert report["triangles_in"] == run_json("info", generated)["triangles"] and report["decimate"]["threads"] == 2


def test_convert_sort_info_compare_reports_equal_the_command(tmp_path, coloured):
    report = meshstream.convert(coloured, tmp_path / "c.glb", compress="meshopt", threads=1)
    command = run_json("convert", coloured, str(tmp_path / "d.glb"), "--compress", "meshopt", "--threads", "1")
    command["outputs"][0]["path"] = str(tmp_path / "c.glb")
    assert without_timings(report) == without_timings(command)
    assert filecmp.cmp(tmp_path / "c.glb", tmp_path / "d.glb", shallow=False)

    report = meshstream.sort(coloured, tmp_path / "s.ply", axis="y", memory="16M")
    command = run_json("sort", coloured, str(tmp_path / "t.ply"), "--axis", "y", "--memory", "16M")
    command["outputs"][0]["path"] = str(tmp_path / "s.ply")
    assert without_timings(report) == without_timings(command)
    assert report["sort"]["axis"] == "y"
    assert filecmp.cmp(tmp_path / "s.ply", tmp_path / "t.ply", shallow=False)

    assert meshstream.info(coloured, topology=True, order=True) == run_json("info", coloured, "--topology", "--order")
    assert meshstream.compare(coloured, tmp_path / "s.ply", samples=20000, attributes=True) == \
        run_json("compare", coloured, str(tmp_path / "s.ply"), "--samples", "20000", "--attributes")


@pytest.mark.skipif(not hasattr(meshstream, "tiles"), reason="built without glTF (MESHSTREAM_WITH_GLTF=OFF)")
def test_tiles_matches_the_command_file_for_file(tmp_path, coloured):
    report = meshstream.tiles(coloured, tmp_path / "py", tile_triangles=8000, threads=2)
    command = run_json("tiles", coloured, str(tmp_path / "cmd"), "--tile-triangles", "8000", "--threads", "2")
    command["outputs"][0]["path"] = str(tmp_path / "py" / "tileset.json")
    assert without_timings(report) == without_timings(command)
    assert report["triangles_in"] == run_json("info", coloured)["triangles"] and report["tiles"]["tiles"] > 1
    def files(root):
        return sorted(os.path.relpath(os.path.join(d, f), root) for d, _, names in os.walk(root) for f in names)

    assert files(tmp_path / "py") == files(tmp_path / "cmd") and len(files(tmp_path / "cmd")) == 1 + report["tiles"]["tiles"]
    assert all(filecmp.cmp(tmp_path / "py" / f, tmp_path / "cmd" / f, shallow=False) for f in files(tmp_path / "cmd"))
    summary = run_json("info", str(tmp_path / "cmd" / "tileset.json"))
    summary["file"] = str(tmp_path / "py" / "tileset.json")
    assert meshstream.info(tmp_path / "py" / "tileset.json") == summary
    # A tileset is not replaced unasked (the setting named), and a cancelled build leaves nothing.
    with pytest.raises(ValueError, match=r"--overwrite"):
        meshstream.tiles(coloured, tmp_path / "py")

    # Raised at the second phase's start, which is always said (counts within a phase come at
    # most every 50 ms: a small tileset's steps can all be quicker than that).
    phases = []

    def interrupt(phase, done, total):
        phases.append(phase)
        if done > 0 or len(set(phases)) > 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        meshstream.tiles(coloured, tmp_path / "cancelled", tile_triangles=8000, progress=interrupt)
    assert sorted(os.listdir(tmp_path)) == ["cmd", "py"]


def test_report_warnings_in_the_commands_words(tmp_path):
    report = meshstream.convert(fixture("ply", "cactus_vcolor.binary_le.ply"), tmp_path / "o.stl", draco_qp=12)
    codes = {w["code"]: w["text"] for w in report["warnings"]}
    assert "--draco-qp" in " ".join(codes.values())
    assert any("colour" in text for text in codes.values())


# ---- errors ----------------------------------------------------------------------------------

def test_errors_carry_file_and_position(tmp_path):
    bad = tmp_path / "bad.stl"
    bad.write_text("solid x\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 oops 0\n")
    with pytest.raises(meshstream.Error) as e:
        meshstream.read(bad)
    assert e.value.file == str(bad) and e.value.line == 5
    assert "oops" in str(e.value) and str(e.value).startswith(str(bad) + ":5")
    # A binary PLY cut short: an offset.
    data = open(fixture("ply", "cactus_vcolor.binary_le.ply"), "rb").read()
    cut = tmp_path / "cut.ply"
    cut.write_bytes(data[:len(data) // 2])
    with pytest.raises(meshstream.Error) as e:
        meshstream.decimate(cut, tmp_path / "never.ply")
    assert e.value.file == str(cut) and e.value.offset is not None and e.value.offset <= len(data) // 2
    assert not os.path.exists(tmp_path / "never.ply")
    with pytest.raises(meshstream.Error) as e:
        meshstream.info(tmp_path / "missing.stl")
    assert e.value.file == str(tmp_path / "missing.stl") and e.value.line is None


def test_bad_arguments_in_the_commands_words(tmp_path, generated):
    out = str(tmp_path / "o.ply")
    with pytest.raises(ValueError, match=r"^--ratio: must be a number in \(0, 1\], found '1.5'$"):
        meshstream.decimate(generated, out, ratio=1.5)
    with pytest.raises(ValueError, match=r"--target: must be a whole number of triangles from 1 to"):
        meshstream.decimate(generated, out, target=0)
    with pytest.raises(ValueError, match=r"--target excludes --ratio|--ratio excludes --target"):
        meshstream.decimate(generated, out, ratio=0.5, target=10)
    with pytest.raises(ValueError, match=r"--sorted-axis: must be x, y or z \(or 0, 1, 2\), found 'w'"):
        meshstream.decimate(generated, out, sorted_axis="w")
    with pytest.raises(ValueError, match=r"--weld: expected a number or a percentage, found '1mm'"):
        meshstream.decimate(generated, out, weld="1mm")
    with pytest.raises(ValueError, match=r"--sort: "):
        meshstream.decimate(generated, out, sort="sometimes")
    with pytest.raises(ValueError, match=r"--memory"):
        meshstream.read(generated, memory="lots")
    with pytest.raises(TypeError, match=r"decimate\(\) got an unexpected keyword argument 'ratoi'"):
        meshstream.decimate(generated, out, ratoi=0.5)
    with pytest.raises(TypeError, match=r"ratio: expected a number, text or a list of them, found dict"):
        meshstream.decimate(generated, out, ratio={})
    with pytest.raises(TypeError):
        meshstream.info(generated, json=True)
    # A setting the library refuses: ValueError, named by its flag.
    with pytest.raises(ValueError, match=r"--target"):
        meshstream.decimate(generated, out, target=10**9)
    assert not os.path.exists(out)


# ---- progress, cancellation, the GIL ---------------------------------------------------------

def test_progress_is_called_with_phases_and_counts(tmp_path, generated):
    seen = []
    meshstream.decimate(generated, tmp_path / "o.stl", ratio=0.5, threads=1,
                        progress=lambda phase, done, total: seen.append((phase, done, total)))
    assert seen and seen[0][0] == "decimating"
    assert all(isinstance(done, int) for _, done, _ in seen)


def test_an_exception_in_progress_cancels_and_removes_the_output(tmp_path, generated):
    out = tmp_path / "o.ply"

    def interrupt(phase, done, total):
        if done > 0:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        meshstream.decimate(generated, out, ratio=0.5, threads=1, progress=interrupt)
    assert not os.path.exists(out) and os.listdir(tmp_path) == []

    def fail(phase, done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        meshstream.convert(generated, out, progress=fail)
    assert os.listdir(tmp_path) == []


def test_ctrl_c_cancels_a_running_decimate(tmp_path, generated):
    # SIGINT to a Python process in the middle of decimate (sent 20 ms after the job began, of
    # the 250 ms it takes): KeyboardInterrupt, no output left.
    out = tmp_path / "o.ply"
    script = (
        "import meshstream, os, signal, threading\n"
        "timer = threading.Timer(0.02, os.kill, (os.getpid(), signal.SIGINT))\n"
        "def started(phase, done, total):\n"
        "    if not timer.is_alive() and not timer.finished.is_set(): timer.start()\n"
        "try:\n"
        f"    meshstream.decimate({generated!r}, {str(out)!r}, ratio=0.01, threads=1, progress=started)\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                            env=os.environ)
    assert result.stdout.strip() == "interrupted", result.stderr
    assert os.listdir(tmp_path) == []


def test_the_gil_is_released_while_a_job_runs(tmp_path, generated):
    ticks = 0
    done = threading.Event()
    thread = threading.Thread(target=lambda: (meshstream.decimate(generated, tmp_path / "o.stl", ratio=0.2,
                                                                  threads=1), done.set()))
    thread.start()
    while not done.is_set() and thread.is_alive():
        ticks += 1
    thread.join()
    assert done.is_set()
    # Held by the job, the GIL would give this loop a handful of turns at most.
    assert ticks > 10000
