// The iterations of the deflated conjugate gradient of yade_electro.solvers.DeflatedCGSolver, in
// C++: Jacobi-preconditioned CG deflated by piecewise-constant vectors on clusters (Saad et al.,
// SIAM J. Sci. Comput. 21, 2000; the same steps as solvers._pcg with `deflate`), with the coarse
// matrix E = W^T A W factorised by Eigen's SimplicialLLT. The Python side keeps the structure
// (clusters, the patterns of W^T A and E) and passes the arrays; a handle keeps E's factor and
// the work vectors between calls.
//
// A: n x n CSR (int32 indptr/indices), W^T A: k x n CSR, lab: cluster of each unknown (int64).
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace {

using SpMat = Eigen::SparseMatrix<double>;

struct Handle {
    int64_t n = 0, k = 0;
    SpMat E;
    Eigen::SimplicialLLT<SpMat> llt;
    bool analyzed = false;
    std::vector<Eigen::Triplet<double>> triplets;
    std::vector<int64_t> e_row, e_col;       // E's pattern (dcg_coarse_pattern)
    std::vector<double> e_val;
    Eigen::VectorXd cv, cy;                 // coarse vectors
    std::vector<double> r, z, p, q;
};

inline void matvec(int64_t n, const int32_t* ip, const int32_t* ix, const double* a, const double* v, double* out) {
    for (int64_t i = 0; i < n; ++i) {
        double s = 0.0;
        for (int32_t t = ip[i]; t < ip[i + 1]; ++t) s += a[t] * v[ix[t]];
        out[i] = s;
    }
}

inline double dot(int64_t n, const double* a, const double* b) {
    double s = 0.0;
    for (int64_t i = 0; i < n; ++i) s += a[i] * b[i];
    return s;
}

}  // namespace

extern "C" void* dcg_create(int64_t n, int64_t k) {
    Handle* h = new Handle();
    h->n = n;
    h->k = k;
    h->E.resize(k, k);
    h->cv.resize(k);
    h->cy.resize(k);
    h->r.resize(n);
    h->z.resize(n);
    h->p.resize(n);
    h->q.resize(n);
    return h;
}

extern "C" void dcg_destroy(void* handle) { delete static_cast<Handle*>(handle); }

// The structural pattern of W^T A (k x n CSR: row c holds every column j with a non-zero (i, j) of A,
// lab[i] = c; columns in the order first met, not sorted) and the entry each non-zero t of A adds
// to (slot[t]), by one pass over A's rows grouped by cluster. out_indices needs room for nnz
// entries. Returns the number of non-zeros of W^T A.
extern "C" int64_t dcg_wta_pattern(int64_t n, int64_t k, const int32_t* ip, const int32_t* ix, const int64_t* lab,
                                   int32_t* out_indptr, int32_t* out_indices, int64_t* slot) {
    std::vector<int64_t> count(k + 1, 0), rows(n);
    for (int64_t i = 0; i < n; ++i) ++count[lab[i] + 1];
    for (int64_t c = 0; c < k; ++c) count[c + 1] += count[c];
    std::vector<int64_t> fill(count.begin(), count.end() - 1);
    for (int64_t i = 0; i < n; ++i) rows[fill[lab[i]]++] = i;         // rows grouped by cluster
    std::vector<int64_t> mark(n, -1), where(n, 0);
    int64_t m = 0;
    out_indptr[0] = 0;
    for (int64_t c = 0; c < k; ++c) {
        for (int64_t r = count[c]; r < count[c + 1]; ++r) {
            const int64_t i = rows[r];
            for (int32_t t = ip[i]; t < ip[i + 1]; ++t) {
                const int32_t j = ix[t];
                if (mark[j] != c) {
                    mark[j] = c;
                    where[j] = m;
                    out_indices[m++] = j;
                }
                slot[t] = where[j];
            }
        }
        out_indptr[c + 1] = (int32_t)m;
    }
    return m;
}

// The pattern of E (key = row * k + col) for dcg_refill, kept in the handle.
extern "C" void dcg_coarse_pattern(void* handle, int64_t m, const int64_t* key) {
    Handle* h = static_cast<Handle*>(handle);
    h->e_row.resize(m);
    h->e_col.resize(m);
    h->e_val.resize(m);
    for (int64_t t = 0; t < m; ++t) {
        h->e_row[t] = key[t] / h->k;
        h->e_col[t] = key[t] % h->k;
    }
}

static int factor_values(Handle* h) {
    const int64_t m = (int64_t)h->e_val.size();
    h->triplets.clear();
    h->triplets.reserve(m);
    for (int64_t t = 0; t < m; ++t) h->triplets.emplace_back(h->e_row[t], h->e_col[t], h->e_val[t]);
    h->E.setFromTriplets(h->triplets.begin(), h->triplets.end());
    if (!h->analyzed) {
        h->llt.analyzePattern(h->E);
        h->analyzed = true;
    }
    h->llt.factorize(h->E);
    return h->llt.info() == Eigen::Success ? 0 : 1;
}

// New values of A (same pattern): the Jacobi inverse diagonal (diag_pos: where each row's
// diagonal sits in a), the values of W^T A (each non-zero t of A adds to wta[wta_slot[t]]) and of
// E (to its entry e_slot[t]), then E's factor. The bincounts of the numpy form, in one pass.
// Returns 0, 1 (E not positive definite) or 2 (a diagonal entry <= 0: inv_d is then not complete).
extern "C" int dcg_refill(void* handle, int64_t nnz, const double* a, const int64_t* diag_pos, double* inv_d,
                          const int64_t* wta_slot, int64_t wta_nnz, double* wta, const int64_t* e_slot) {
    Handle* h = static_cast<Handle*>(handle);
    for (int64_t i = 0; i < h->n; ++i) {
        const double d = a[diag_pos[i]];
        if (!(d > 0.0)) return 2;
        inv_d[i] = 1.0 / d;
    }
    std::fill(wta, wta + wta_nnz, 0.0);
    std::fill(h->e_val.begin(), h->e_val.end(), 0.0);
    for (int64_t t = 0; t < nnz; ++t) {
        wta[wta_slot[t]] += a[t];
        h->e_val[e_slot[t]] += a[t];
    }
    return factor_values(h);
}

// Solve A x = b from x (in place) to ||b - A x|| <= max(rtol ||b||, atol). out = [iterations,
// relative residual ||b - A x|| / ||b||, status]: status 0 done (the caller checks the residual),
// 2 breakdown (p.Ap <= 0: A not positive definite; out[1] is then p.Ap).
extern "C" void dcg_solve(void* handle, const int32_t* ip, const int32_t* ix, const double* a, const double* inv_d,
                          const int64_t* lab, const int32_t* wip, const int32_t* wix, const double* wa, const double* b,
                          double* x, double rtol, double atol, int64_t maxiter, double* out) {
    Handle* h = static_cast<Handle*>(handle);
    const int64_t n = h->n, k = h->k;
    double* r = h->r.data();
    double* z = h->z.data();
    double* p = h->p.data();
    double* q = h->q.data();
    out[0] = 0.0;
    out[1] = 0.0;
    out[2] = 0.0;
    const double nb = std::sqrt(dot(n, b, b));
    if (nb == 0.0) {
        for (int64_t i = 0; i < n; ++i) x[i] = 0.0;
        return;
    }
    const double tol = std::max(rtol * nb, atol);
    auto residual = [&]() {                  // r = b - A x
        matvec(n, ip, ix, a, x, r);
        for (int64_t i = 0; i < n; ++i) r[i] = b[i] - r[i];
    };
    auto coarse_solve = [&]() { h->cy = h->llt.solve(h->cv); };     // cy = E^-1 cv
    residual();
    if (std::sqrt(dot(n, r, r)) > nb) {      // a start worse than zero
        for (int64_t i = 0; i < n; ++i) { x[i] = 0.0; r[i] = b[i]; }
    }
    // x += W E^-1 W^T r: the coarse error components at once
    h->cv.setZero();
    for (int64_t i = 0; i < n; ++i) h->cv[lab[i]] += r[i];
    coarse_solve();
    for (int64_t i = 0; i < n; ++i) x[i] += h->cy[lab[i]];
    residual();
    double rn = std::sqrt(dot(n, r, r));
    int64_t it = 0;
    // p -= W E^-1 (W^T A) z
    auto project_out = [&](double* target) {
        for (int64_t c = 0; c < k; ++c) {
            double s = 0.0;
            for (int32_t t = wip[c]; t < wip[c + 1]; ++t) s += wa[t] * z[wix[t]];
            h->cv[c] = s;
        }
        coarse_solve();
        for (int64_t i = 0; i < n; ++i) target[i] -= h->cy[lab[i]];
    };
    if (rn > tol) {
        for (int64_t i = 0; i < n; ++i) { z[i] = inv_d[i] * r[i]; p[i] = z[i]; }
        project_out(p);
        double rz = dot(n, r, z);
        while (it < maxiter) {
            ++it;
            matvec(n, ip, ix, a, p, q);
            const double pq = dot(n, p, q);
            if (!(pq > 0.0)) {
                out[0] = (double)it;
                out[1] = pq;
                out[2] = 2.0;
                return;
            }
            const double alpha = rz / pq;
            double rr = 0.0, rz_new = 0.0;
            for (int64_t i = 0; i < n; ++i) {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
                rr += r[i] * r[i];
                z[i] = inv_d[i] * r[i];
                rz_new += r[i] * z[i];
            }
            rn = std::sqrt(rr);
            if (rn <= tol) break;
            const double beta = rz_new / rz;
            for (int64_t i = 0; i < n; ++i) p[i] = beta * p[i] + z[i];
            project_out(p);
            rz = rz_new;
        }
    }
    residual();
    out[0] = (double)it;
    out[1] = std::sqrt(dot(n, r, r)) / nb;
}
