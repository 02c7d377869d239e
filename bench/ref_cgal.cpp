// Bench-only quality reference (bench/decimate.sh): CGAL's in-core greedy edge collapse with
// Garland–Heckbert plane quadrics and optimal placement (Surface_mesh_simplification with
// GarlandHeckbert_plane_policies), the quality the paper compares itself with. Reads a soup,
// welds and orients it (Polygon_mesh_processing), collapses until the face count reaches the
// target, writes. Prints "ref_cgal: in N out M seconds S" on stderr.
//   ref_cgal IN OUT --target N
#include "io/error.hpp"
#include "io/format.hpp"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace SMS = CGAL::Surface_mesh_simplification;
namespace PMP = CGAL::Polygon_mesh_processing;

// Stops when the mesh has at most `target` faces (CGAL 5.5's count predicates count edges).
struct FaceCountStop {
    size_t target;
    template <class Profile>
    bool operator()(const double&, const Profile& profile, std::size_t, std::size_t) const {
        return profile.surface_mesh().number_of_faces() <= target;
    }
};

int main(int argc, char** argv) {
    using namespace meshstream;
    if (argc != 5 || std::string(argv[3]) != "--target") {
        std::fprintf(stderr, "usage: ref_cgal IN OUT --target TRIANGLES\n");
        return 2;
    }
    size_t target = std::strtoull(argv[4], nullptr, 10);
    auto start = std::chrono::steady_clock::now();
    try {
        std::vector<Point> points;
        std::vector<std::array<size_t, 3>> faces;
        size_t in_count = 0;
        {
            io::Input in = io::open_input(argv[1]);
            io::TriangleChunk chunk;
            while (in.reader->next(chunk)) {
                auto xyz = chunk.xyz();
                for (size_t t = 0; t < chunk.size(); ++t, ++in_count) {
                    std::array<size_t, 3> f;
                    for (int c = 0; c < 3; ++c) {
                        f[c] = points.size();
                        points.emplace_back(xyz[9 * t + 3 * c], xyz[9 * t + 3 * c + 1], xyz[9 * t + 3 * c + 2]);
                    }
                    faces.push_back(f);
                }
            }
        }
        PMP::repair_polygon_soup(points, faces);  // merges duplicate points, drops degenerate faces
        PMP::orient_polygon_soup(points, faces);  // duplicates non-manifold vertices as needed
        Mesh mesh;
        PMP::polygon_soup_to_polygon_mesh(points, faces, mesh);
        points.clear();
        faces.clear();
        SMS::GarlandHeckbert_plane_policies<Mesh, Kernel> gh(mesh);
        SMS::edge_collapse(mesh, FaceCountStop{target},
                           CGAL::parameters::get_cost(gh.get_cost()).get_placement(gh.get_placement()));
        mesh.collect_garbage();
        io::Output o = io::open_output(argv[2], "", {});
        io::TriangleChunk chunk;
        for (auto f : mesh.faces()) {
            float* t = chunk.push_slot();
            int c = 0;
            for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
                if (c == 3) break;
                const Point& p = mesh.point(v);
                t[3 * c] = float(p.x());
                t[3 * c + 1] = float(p.y());
                t[3 * c + 2] = float(p.z());
                ++c;
            }
            if (chunk.full()) {
                o.write(chunk);
                chunk.clear();
            }
        }
        if (!chunk.empty()) o.write(chunk);
        o.finish();
        double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::fprintf(stderr, "ref_cgal: in %zu out %zu seconds %.3f\n", in_count, size_t(mesh.number_of_faces()),
                     seconds);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ref_cgal: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
