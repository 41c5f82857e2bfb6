// Delaunay triangulation of a 3D point set with CGAL (exact predicates, inexact
// constructions), for yade_electro.tessellation. Built on first use by
// yade_electro/native/__init__.py (g++, Debian's libcgal-dev).
//
//   delaunay_cgal IN OUT
//   IN : int64 n, then n x 3 float64 points
//   OUT: int64 n_vertices, int64 n_cells, then n_cells x 4 int64 point indices (positively
//        oriented finite cells), then n_cells x 3 float64 circumcentres
// Exit 2 on a usage or I/O error, 3 when points coincide (n_vertices < n).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <cstdint>
#include <cstdio>
#include <vector>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Triangulation_vertex_base_with_info_3<std::int64_t, K> Vb;
typedef CGAL::Delaunay_triangulation_cell_base_3<K> Cb;
typedef CGAL::Triangulation_data_structure_3<Vb, Cb> Tds;
typedef CGAL::Delaunay_triangulation_3<K, Tds> DT;

int main(int argc, char** argv) {
    if (argc != 3) { std::fprintf(stderr, "usage: delaunay_cgal IN OUT\n"); return 2; }
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
    FILE* out = std::fopen(argv[2], "wb");
    if (!out) { std::perror(argv[2]); return 2; }
    std::fwrite(&nv, sizeof nv, 1, out);
    std::fwrite(&nc, sizeof nc, 1, out);
    std::vector<std::int64_t> cell(4 * 65536);
    std::vector<double> cc(3 * 65536);
    std::vector<double> all_cc;
    all_cc.reserve(3 * nc);
    size_t k = 0;
    for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
        for (int j = 0; j < 4; ++j) cell[4 * k + j] = c->vertex(j)->info();
        K::Point_3 p = CGAL::circumcenter(c->vertex(0)->point(), c->vertex(1)->point(),
                                          c->vertex(2)->point(), c->vertex(3)->point());
        all_cc.push_back(p.x()); all_cc.push_back(p.y()); all_cc.push_back(p.z());
        if (++k == 65536) { std::fwrite(cell.data(), sizeof(std::int64_t), 4 * k, out); k = 0; }
    }
    if (k) std::fwrite(cell.data(), sizeof(std::int64_t), 4 * k, out);
    std::fwrite(all_cc.data(), sizeof(double), all_cc.size(), out);
    if (std::fclose(out) != 0) { std::perror(argv[2]); return 2; }
    return nv < n ? 3 : 0;
}
