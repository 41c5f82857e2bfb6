// Contact radii of the granular mode's sphere pairs (yade_electro.conductance.contact_radius),
// and the centre distances of node pairs (conductance.edge_lengths), compiled: one pass over
// the pairs instead of numpy's temporaries. The numpy form's operations in its order, built
// without floating-point contraction.
//
// pos (n, 3), radius (n,), edges (m, 2) int64 row-major; shift (m, 3) or null (the periodic
// image of node j next to node i); model 0 geometric (the lens where the spheres' surfaces
// cross), 1 Hertz (sqrt(R* delta)). Returns the number of pairs with coincident centres (0 when
// all is well; out is then not meaningful).
#include <cmath>
#include <cstdint>

namespace {

// |x_j - x_i (+ shift of pair t)| of pair t = (i, j)
inline double pair_distance(int64_t t, const double* pos, const int64_t* edges, const double* shift) {
    const int64_t i = edges[2 * t], j = edges[2 * t + 1];
    double d0 = pos[3 * j] - pos[3 * i];
    double d1 = pos[3 * j + 1] - pos[3 * i + 1];
    double d2 = pos[3 * j + 2] - pos[3 * i + 2];
    if (shift) {
        d0 += shift[3 * t];
        d1 += shift[3 * t + 1];
        d2 += shift[3 * t + 2];
    }
    return std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

}  // namespace

extern "C" int64_t contact_radii(int64_t m, const double* pos, const double* radius, const int64_t* edges,
                                 const double* shift, int model, double* out) {
    int64_t coincident = 0;
    for (int64_t t = 0; t < m; ++t) {
        const double d = pair_distance(t, pos, edges, shift);
        if (!(d > 0.0)) {
            ++coincident;
            out[t] = 0.0;
            continue;
        }
        const double r1 = radius[edges[2 * t]], r2 = radius[edges[2 * t + 1]];
        if (model == 1) {
            double delta = r1 + r2 - d;
            if (delta < 0.0) delta = 0.0;
            out[t] = std::sqrt(r1 * r2 / (r1 + r2) * delta);
        } else {
            const double x = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
            double a2 = d < r1 + r2 ? r1 * r1 - x * x : 0.0;
            if (a2 < 0.0) a2 = 0.0;
            out[t] = std::sqrt(a2);
        }
    }
    return coincident;
}

// The distance |x_j - x_i (+ shift)| of each pair; returns the number of zero distances.
extern "C" int64_t pair_lengths(int64_t m, const double* pos, const int64_t* edges, const double* shift,
                                double* out) {
    int64_t zero = 0;
    for (int64_t t = 0; t < m; ++t) {
        out[t] = pair_distance(t, pos, edges, shift);
        if (!(out[t] > 0.0)) ++zero;
    }
    return zero;
}
