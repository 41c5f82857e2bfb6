// Hop distances on a bond graph, for the crack rules of the 'voronoi' law
// (yade_electro.voronoi.VoronoiFaces.linked): for each node pair (i, j), is j within `hops`
// bonds of i?  Built by yade_electro.native as a shared library and called through ctypes.
//
// The bonds are a symmetric CSR adjacency (indptr, indices) of n nodes. For pairs grouped by
// i (any order works; grouped pairs reuse the marks), the nodes within a = ceil(hops / 2)
// bonds of i are stamped with i's stamp by a breadth-first search; a pair is linked when a
// node within b = hops - a bonds of j carries that stamp. Memory: two int64 stamps per node
// and the search fronts; time: about (ball of radius a + pairs x ball of radius b).
#include <cstdint>
#include <vector>

extern "C" int graph_hops_linked(int64_t n, const int64_t* indptr, const int64_t* indices, int64_t p,
                                 const int64_t* pi, const int64_t* pj, int64_t hops, uint8_t* out) {
    if (n < 0 || p < 0 || hops < 0) return 1;
    const int64_t a = (hops + 1) / 2, b = hops - a;
    std::vector<int64_t> mark(n, -1), seen(n, -1);
    std::vector<int64_t> front, next;
    int64_t current = -1;
    for (int64_t k = 0; k < p; ++k) {
        const int64_t i = pi[k], j = pj[k];
        if (i < 0 || i >= n || j < 0 || j >= n) return 2;
        if (i != current) {                      // stamp the ball of radius a around i
            current = i;
            mark[i] = i;
            front.assign(1, i);
            for (int64_t d = 0; d < a && !front.empty(); ++d) {
                next.clear();
                for (int64_t u : front)
                    for (int64_t e = indptr[u]; e < indptr[u + 1]; ++e) {
                        const int64_t v = indices[e];
                        if (mark[v] != i) { mark[v] = i; next.push_back(v); }
                    }
                front.swap(next);
            }
        }
        // search the ball of radius b around j for a stamped node
        uint8_t hit = mark[j] == i;
        if (!hit && b > 0) {
            seen[j] = k;
            front.assign(1, j);
            for (int64_t d = 0; d < b && !front.empty() && !hit; ++d) {
                next.clear();
                for (int64_t u : front) {
                    for (int64_t e = indptr[u]; e < indptr[u + 1]; ++e) {
                        const int64_t v = indices[e];
                        if (mark[v] == i) { hit = 1; break; }
                        if (seen[v] != k) { seen[v] = k; next.push_back(v); }
                    }
                    if (hit) break;
                }
                front.swap(next);
            }
        }
        out[k] = hit;
    }
    return 0;
}
