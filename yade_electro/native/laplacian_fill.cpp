// The values of a condensed network Laplacian's unknown block K_uu from new edge values, in one
// compiled pass: what yade_electro.condensation.ReducedSystem.assemble does with numpy (a
// scatter of -c to each unknown-unknown edge's two off-diagonal entries, the unknowns'
// incidence matrix times c for the diagonal, plus an optional extra diagonal). With one edge per
// off-diagonal entry (the usual case) these are the numpy form's operations in its order, so the
// values are the same to the last bit; repeated edges add up in another order (rounding only).
//
// data: K_uu's CSR values (nnz); c: the edge values (m); e_uu: the edge of each of the nuu
// unknown-unknown pairs (null: pair t is edge t); o1, o2: the two off-diagonal entries of pair t
// in data; diag: each unknown's diagonal entry; inc_ip, inc_ix: the unknowns' incidence matrix
// (nu x m CSR of ones; row i lists the edges of unknown i); extra: a diagonal to add (or null).
#include <cstdint>

namespace {

template <typename I, typename P, typename J>
void fill(int64_t nnz, double* data, const double* c, int64_t nuu, const I* e_uu, const I* o1, const I* o2,
          int64_t nu, const int64_t* diag, const P* inc_ip, const J* inc_ix, const double* extra) {
    for (int64_t t = 0; t < nnz; ++t) data[t] = 0.0;
    for (int64_t t = 0; t < nuu; ++t) {
        const double v = c[e_uu ? (int64_t)e_uu[t] : t];
        data[o1[t]] -= v;
        data[o2[t]] -= v;
    }
    for (int64_t i = 0; i < nu; ++i) {
        double s = 0.0;
        for (P t = inc_ip[i]; t < inc_ip[i + 1]; ++t) s += c[inc_ix[t]];
        data[diag[i]] += s;
        if (extra) data[diag[i]] += extra[i];
    }
}

}  // namespace

// index widths: pairs/slots (I), incidence indptr (P) and indices (J), 32 or 64 bits each
#define LAPLACIAN_FILL(NAME, I, P, J)                                                                         \
    extern "C" void NAME(int64_t nnz, double* data, const double* c, int64_t nuu, const I* e_uu, const I* o1,  \
                         const I* o2, int64_t nu, const int64_t* diag, const P* inc_ip, const J* inc_ix,       \
                         const double* extra) {                                                              \
        fill<I, P, J>(nnz, data, c, nuu, e_uu, o1, o2, nu, diag, inc_ip, inc_ix, extra);                     \
    }

LAPLACIAN_FILL(laplacian_fill_i32_p32_j32, int32_t, int32_t, int32_t)
LAPLACIAN_FILL(laplacian_fill_i32_p64_j32, int32_t, int64_t, int32_t)
LAPLACIAN_FILL(laplacian_fill_i32_p64_j64, int32_t, int64_t, int64_t)
LAPLACIAN_FILL(laplacian_fill_i64_p32_j32, int64_t, int32_t, int32_t)
LAPLACIAN_FILL(laplacian_fill_i64_p64_j32, int64_t, int64_t, int32_t)
LAPLACIAN_FILL(laplacian_fill_i64_p64_j64, int64_t, int64_t, int64_t)
