// Delaunay triangulation of a 3D point set with CGAL (exact predicates, inexact
// constructions), for yade_electro.geometry.tessellation. Built at install by setup.py
// (g++, Debian's libcgal-dev).
//
//   delaunay_cgal IN OUT N_REAL
//   IN : int64 n, then n x 3 float64 points
//   OUT: int64 n_vertices, n_cells, n_edges, n_incidences; then n_cells x 4 int64 point
//        indices (finite cells); n_cells x 3 float64 circumcentres; n_edges x 2 int64 point
//        pairs (the Delaunay edges with a point < N_REAL: the Voronoi faces); n_edges int64
//        counts; n_incidences int64 cells around each edge, in cyclic order (the face's
//        polygon, ordered)
// Exit 2 on a usage or I/O error, 3 when points coincide (n_vertices < n).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Triangulation_vertex_base_with_info_3<std::int64_t, K> Vb;
typedef CGAL::Triangulation_cell_base_with_info_3<std::int64_t, K, CGAL::Delaunay_triangulation_cell_base_3<K>> Cb;
typedef CGAL::Triangulation_data_structure_3<Vb, Cb> Tds;
typedef CGAL::Delaunay_triangulation_3<K, Tds> DT;

int main(int argc, char** argv) {
    if (argc != 4) { std::fprintf(stderr, "usage: delaunay_cgal IN OUT N_REAL\n"); return 2; }
    const std::int64_t n_real = std::atoll(argv[3]);
    FILE* in = std::fopen(argv[1], "rb");
    if (!in) { std::perror(argv[1]); return 2; }
    std::int64_t n = 0;
    if (std::fread(&n, sizeof n, 1, in) != 1 || n < 4) { std::fprintf(stderr, "bad header\n"); return 2; }
    std::vector<double> xyz(3 * n);
    if (std::fread(xyz.data(), sizeof(double), 3 * n, in) != (size_t)(3 * n)) { std::fprintf(stderr, "short input\n"); return 2; }
    std::fclose(in);
    std::vector<std::pair<K::Point_3, std::int64_t>> pts;
    pts.reserve(n);
    for (std::int64_t i = 0; i < n; ++i) pts.emplace_back(K::Point_3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]), i);
    std::vector<double>().swap(xyz);
    DT dt(pts.begin(), pts.end());                 // spatially sorted insertion
    std::vector<std::pair<K::Point_3, std::int64_t>>().swap(pts);
    std::int64_t nv = dt.number_of_vertices(), nc = dt.number_of_finite_cells();
    std::vector<std::int64_t> cells;
    std::vector<double> cc;
    cells.reserve(4 * nc);
    cc.reserve(3 * nc);
    std::int64_t k = 0;
    for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c, ++k) {
        c->info() = k;
        for (int j = 0; j < 4; ++j) cells.push_back(c->vertex(j)->info());
        K::Point_3 p = CGAL::circumcenter(c->vertex(0)->point(), c->vertex(1)->point(),
                                          c->vertex(2)->point(), c->vertex(3)->point());
        cc.push_back(p.x()); cc.push_back(p.y()); cc.push_back(p.z());
    }
    std::vector<std::int64_t> pairs, counts, around;
    for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
        std::int64_t a = e->first->vertex(e->second)->info(), b = e->first->vertex(e->third)->info();
        if (std::min(a, b) >= n_real) continue;
        auto circ = dt.incident_cells(*e), done = circ;
        std::int64_t m = 0;
        do {
            if (!dt.is_infinite(circ)) { around.push_back(circ->info()); ++m; }
        } while (++circ != done);
        pairs.push_back(std::min(a, b)); pairs.push_back(std::max(a, b));
        counts.push_back(m);
    }
    std::int64_t ne = counts.size(), ni = around.size();
    FILE* out = std::fopen(argv[2], "wb");
    if (!out) { std::perror(argv[2]); return 2; }
    std::int64_t head[4] = {nv, nc, ne, ni};
    std::fwrite(head, sizeof(std::int64_t), 4, out);
    std::fwrite(cells.data(), sizeof(std::int64_t), cells.size(), out);
    std::fwrite(cc.data(), sizeof(double), cc.size(), out);
    std::fwrite(pairs.data(), sizeof(std::int64_t), pairs.size(), out);
    std::fwrite(counts.data(), sizeof(std::int64_t), counts.size(), out);
    std::fwrite(around.data(), sizeof(std::int64_t), around.size(), out);
    if (std::fclose(out) != 0) { std::perror(argv[2]); return 2; }
    return nv < n ? 3 : 0;
}
