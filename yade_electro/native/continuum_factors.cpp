// The geometric factors of the `continuum` law (paper 000 eq. 3-5), compiled: for every edge
// (i, j), g = sqrt(S_i S_j) / l_ij with S_i = alpha(n_i) r_i^2 / f_i, f_i the eccentricity
// factor of node i (``factor`` where |barycentre of its neighbours - x_i| / r_i > threshold
// (1 + 1e-9), else 1). One pass over the edges for the barycentres, one over the nodes, one
// over the edges for g, where numpy (yade_electro.surfaces) makes a dozen temporaries.
//
// pos (n, 3), radius (n,), alpha_r2 (n,) = alpha(n_i) r_i^2 [m^2], edges (m, 2) int64
// row-major, all bonds of the graph. Work arrays: sum (n, 3), count (n,). Returns the number of
// edges with coincident centres (g is then not meaningful).
#include <cmath>
#include <cstdint>

extern "C" int64_t continuum_factors(int64_t n, const double* pos, const double* radius, const double* alpha_r2,
                                     int64_t m, const int64_t* edges, double threshold, double factor,
                                     double* sum, int64_t* count, double* surface, double* out) {
    for (int64_t k = 0; k < 3 * n; ++k) sum[k] = 0.0;
    for (int64_t k = 0; k < n; ++k) count[k] = 0;
    for (int64_t t = 0; t < m; ++t) {
        const int64_t i = edges[2 * t], j = edges[2 * t + 1];
        for (int c = 0; c < 3; ++c) {
            sum[3 * i + c] += pos[3 * j + c];
            sum[3 * j + c] += pos[3 * i + c];
        }
        ++count[i];
        ++count[j];
    }
    const double limit = threshold * (1.0 + 1e-9);
    for (int64_t k = 0; k < n; ++k) {
        double f = 1.0;
        if (count[k] > 0) {
            double e2 = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double d = sum[3 * k + c] / (double)count[k] - pos[3 * k + c];
                e2 += d * d;
            }
            if (std::sqrt(e2) / radius[k] > limit) f = factor;
        }
        surface[k] = alpha_r2[k] / f;
    }
    int64_t coincident = 0;
    for (int64_t t = 0; t < m; ++t) {
        const int64_t i = edges[2 * t], j = edges[2 * t + 1];
        double l2 = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double d = pos[3 * j + c] - pos[3 * i + c];
            l2 += d * d;
        }
        const double l = std::sqrt(l2);
        if (!(l > 0.0)) {
            ++coincident;
            out[t] = 0.0;
            continue;
        }
        out[t] = std::sqrt(surface[i] * surface[j]) / l;
    }
    return coincident;
}
