// The sparsity pattern of a CSR matrix from (row, col) pairs, compiled: what
// yade_electro.condensation._pattern gets from scipy's COO -> CSR conversion (a counting sort by
// row, then the columns sorted within each row), with the position in ``data`` of every input
// pair. One call instead of scipy's conversion, duplicate sum and index sort.
//
// rows, cols (N,) int64; outputs indptr (nr + 1,) int32, indices (N,) int32, slot (N,) int64.
// Returns N, or -1 when a (row, col) pair repeats (the caller then takes the general path,
// which adds repeated pairs up).
#include <algorithm>
#include <cstdint>
#include <vector>

extern "C" int64_t csr_pattern(int64_t nr, int64_t N, const int64_t* rows, const int64_t* cols, int32_t* indptr,
                               int32_t* indices, int64_t* slot) {
    std::vector<int64_t> start(nr + 1, 0);
    for (int64_t k = 0; k < N; ++k) ++start[rows[k] + 1];
    for (int64_t r = 0; r < nr; ++r) start[r + 1] += start[r];
    std::vector<int64_t> order(N), next(start.begin(), start.end() - 1);
    for (int64_t k = 0; k < N; ++k) order[next[rows[k]]++] = k;          // stable by row
    for (int64_t r = 0; r < nr; ++r) {
        const int64_t a = start[r], b = start[r + 1];
        std::sort(order.begin() + a, order.begin() + b, [cols](int64_t x, int64_t y) {
            return cols[x] < cols[y] || (cols[x] == cols[y] && x < y);
        });
        for (int64_t p = a; p < b; ++p) {
            if (p > a && cols[order[p]] == cols[order[p - 1]]) return -1;
            indices[p] = (int32_t)cols[order[p]];
            slot[order[p]] = p;
        }
        indptr[r] = (int32_t)a;
    }
    indptr[nr] = (int32_t)N;
    return N;
}
