// Pair forces of the soft-sphere overlap energy of the jamming (yade_electro.packing.jamming):
// the sphere-sphere part of Relaxer.forces, in the same order of operations as its numpy form,
// so that the result is the same to the last bit (built without FP contraction).
//
// For every pair (i, j) of the Verlet list (pairs: n_pairs x 2, row-major) with d = x_j - x_i, d2 = |d|^2 and
// rs = s (rho_i + rho_j): if d2 < rs^2, ov = rs - sqrt(d2) and f = d ov / max(sqrt(d2), 1e-12);
// by_j[j] += f and by_i[i] += f (the two bincounts of the numpy form, summed in pair order).
// F = by_j - by_i. The overlaps are written in pair order to ov_out (for the energy, summed by
// the caller as numpy does). Returns the number of overlapping pairs; *maxov their largest
// overlap (0 if none).
#include <cmath>
#include <cstdint>
#include <vector>

extern "C" int64_t soft_sphere_forces(int64_t n, const double* x, const double* rho, double s, int64_t n_pairs,
                                      const int64_t* pairs, double* F, double* ov_out,
                                      double* maxov) {
    std::vector<double> by_i(3 * n, 0.0), by_j(3 * n, 0.0);
    int64_t m = 0;
    double mx = 0.0;
    bool any = false;
    for (int64_t p = 0; p < n_pairs; ++p) {
        const int64_t i = pairs[2 * p], j = pairs[2 * p + 1];
        const double d0 = x[3 * j] - x[3 * i], d1 = x[3 * j + 1] - x[3 * i + 1], d2c = x[3 * j + 2] - x[3 * i + 2];
        const double a0 = d0 * d0, a1 = d1 * d1, a2 = d2c * d2c;
        const double d2 = (a0 + a2) + a1;    // numpy 1.24 einsum("ij,ij->i") on 3 columns sums in this order
        const double rs = s * (rho[i] + rho[j]);
        if (!(d2 < rs * rs)) continue;
        const double dist = std::sqrt(d2);
        const double ov = rs - dist;
        if (!any || ov > mx) mx = ov;
        any = true;
        ov_out[m++] = ov;
        const double q = ov / (dist > 1e-12 ? dist : 1e-12);
        const double f0 = d0 * q, f1 = d1 * q, f2 = d2c * q;
        by_j[3 * j] += f0; by_j[3 * j + 1] += f1; by_j[3 * j + 2] += f2;
        by_i[3 * i] += f0; by_i[3 * i + 1] += f1; by_i[3 * i + 2] += f2;
    }
    for (int64_t k = 0; k < 3 * n; ++k) F[k] = 0.0 + (by_j[k] - by_i[k]);
    *maxov = mx;
    return m;
}
