// The vector work of one FIRE step of the jamming (yade_electro.packing.jamming) for large packings
// in spatial order: the sphere-sphere forces and energy, the FIRE power and norms, the velocity
// mix and the move, and the largest displacement since the Verlet list was made. One pass over the
// arrays each, no temporaries: at 1M spheres numpy's form makes and reads a 24 MB array per
// operation. Not the same bits as numpy's form (the sums run in another order): used only where
// the spheres were reordered anyway (SPATIAL_ORDER_FROM).
//
// Arrays are C-contiguous: x, v, F (n x 3), rho (n), pairs (n_pairs x 2, int64).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <thread>
#include <vector>

// F = forces of 1/2 sum max(0, s (rho_i + rho_j) - d_ij)^2 over the pairs: for d = x_j - x_i and
// ov = s (rho_i + rho_j) - |d| > 0, f = d ov / max(|d|, 1e-12), F_j += f, F_i -= f.
// out[0] = energy (1/2 sum ov^2), out[1] = largest overlap (0 if none). Returns the number of
// overlapping pairs. With threads = 2 the pairs are split in two halves, the second half's forces
// go to a buffer of its own that is added at the end.
struct PairPart {
    double energy = 0.0, mx = 0.0;
    int64_t m = 0;
};

static void pair_part(const double* x, const double* rho, double s, const int64_t* pairs, int64_t p0, int64_t p1,
                      double* F, PairPart* out) {
    PairPart r;
    for (int64_t p = p0; p < p1; ++p) {
        const int64_t i = pairs[2 * p], j = pairs[2 * p + 1];
        const double d0 = x[3 * j] - x[3 * i], d1 = x[3 * j + 1] - x[3 * i + 1], d2 = x[3 * j + 2] - x[3 * i + 2];
        const double dd = d0 * d0 + d1 * d1 + d2 * d2;
        const double rs = s * (rho[i] + rho[j]);
        if (!(dd < rs * rs)) continue;
        const double dist = std::sqrt(dd);
        const double ov = rs - dist;
        ++r.m;
        r.energy += ov * ov;
        if (ov > r.mx) r.mx = ov;
        const double q = ov / (dist > 1e-12 ? dist : 1e-12);
        const double f0 = d0 * q, f1 = d1 * q, f2 = d2 * q;
        F[3 * j] += f0; F[3 * j + 1] += f1; F[3 * j + 2] += f2;
        F[3 * i] -= f0; F[3 * i + 1] -= f1; F[3 * i + 2] -= f2;
    }
    *out = r;
}

extern "C" int64_t fire_pair_forces(int64_t n, const double* x, const double* rho, double s, int64_t n_pairs,
                                    const int64_t* pairs, double* F, double* out, int64_t threads) {
    std::fill(F, F + 3 * n, 0.0);
    PairPart a, b;
    if (threads < 2 || n_pairs < 100000) {
        pair_part(x, rho, s, pairs, 0, n_pairs, F, &a);
    } else {
        std::vector<double> G(3 * n, 0.0);
        const int64_t half = n_pairs / 2;
        std::thread t(pair_part, x, rho, s, pairs, half, n_pairs, G.data(), &b);
        pair_part(x, rho, s, pairs, 0, half, F, &a);
        t.join();
        for (int64_t k = 0; k < 3 * n; ++k) F[k] += G[k];
    }
    out[0] = 0.5 * (a.energy + b.energy);
    out[1] = std::max(a.mx, b.mx);
    return a.m + b.m;
}

// out = [max_i |F_i|^2, F.v, v.v, F.F]
extern "C" void fire_power(int64_t n, const double* F, const double* v, double* out) {
    double fmax2 = 0.0, P = 0.0, vv = 0.0, ff = 0.0;
    for (int64_t i = 0; i < n; ++i) {
        const double* f = F + 3 * i;
        const double* w = v + 3 * i;
        const double f2 = f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
        if (f2 > fmax2) fmax2 = f2;
        ff += f2;
        P += f[0] * w[0] + f[1] * w[1] + f[2] * w[2];
        vv += w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    }
    out[0] = fmax2; out[1] = P; out[2] = vv; out[3] = ff;
}

// v = a v + b F (a = 0: v = b F), then v += dt F and x += dt v
extern "C" void fire_move(int64_t n, double* x, double* v, const double* F, double a, double b, double dt) {
    for (int64_t k = 0; k < 3 * n; ++k) {
        const double w = (a == 0.0 ? 0.0 : a * v[k]) + b * F[k] + dt * F[k];
        v[k] = w;
        x[k] += dt * w;
    }
}

// max_i |x_i - ref_i|^2
extern "C" double fire_max_move2(int64_t n, const double* x, const double* ref) {
    double mx = 0.0;
    for (int64_t i = 0; i < n; ++i) {
        const double a = x[3 * i] - ref[3 * i], b = x[3 * i + 1] - ref[3 * i + 1], c = x[3 * i + 2] - ref[3 * i + 2];
        const double d = a * a + b * b + c * c;
        if (d > mx) mx = d;
    }
    return mx;
}

// The Verlet list: every pair i < j with |x_j - x_i| < cut, found through a grid of cubic cells of
// side >= cut (each sphere against its own cell and the 26 around it). Pairs come out sorted by i
// (the spheres' order, spatial in this use), then by cell. Writes at most `capacity` pairs to
// `pairs` (row-major, int64) and returns how many there are: the caller calls again with more room
// when that is larger than `capacity`. Returns -1 if the grid would be too large.
extern "C" int64_t fire_pairs_within(int64_t n, const double* x, double cut, int64_t capacity, int64_t* pairs) {
    if (n < 2) return 0;
    double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
    for (int64_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], x[3 * i + k]);
            hi[k] = std::max(hi[k], x[3 * i + k]);
        }
    int64_t dim[3];
    int64_t cells = 1;
    for (int k = 0; k < 3; ++k) {
        dim[k] = std::max<int64_t>(1, (int64_t)std::floor((hi[k] - lo[k]) / cut));
        cells *= dim[k];
        if (cells > (int64_t)1 << 31) return -1;
    }
    double inv[3];
    for (int k = 0; k < 3; ++k) inv[k] = dim[k] / std::max(hi[k] - lo[k], 1e-300);   // cell side >= cut
    std::vector<int64_t> cell_of(n);
    std::vector<int64_t> start(cells + 1, 0);
    for (int64_t i = 0; i < n; ++i) {
        int64_t c[3];
        for (int k = 0; k < 3; ++k) c[k] = std::min<int64_t>(dim[k] - 1, (int64_t)((x[3 * i + k] - lo[k]) * inv[k]));
        cell_of[i] = (c[0] * dim[1] + c[1]) * dim[2] + c[2];
        ++start[cell_of[i] + 1];
    }
    for (int64_t c = 0; c < cells; ++c) start[c + 1] += start[c];
    std::vector<int64_t> members(n), fill(start.begin(), start.end() - 1);
    for (int64_t i = 0; i < n; ++i) members[fill[cell_of[i]]++] = i;     // increasing i within a cell
    const double cut2 = cut * cut;
    int64_t m = 0;
    for (int64_t i = 0; i < n; ++i) {
        const int64_t ci = cell_of[i];
        const int64_t c0 = ci / (dim[1] * dim[2]), c1 = (ci / dim[2]) % dim[1], c2 = ci % dim[2];
        for (int64_t a = std::max<int64_t>(0, c0 - 1); a <= std::min(dim[0] - 1, c0 + 1); ++a)
            for (int64_t b = std::max<int64_t>(0, c1 - 1); b <= std::min(dim[1] - 1, c1 + 1); ++b)
                for (int64_t d = std::max<int64_t>(0, c2 - 1); d <= std::min(dim[2] - 1, c2 + 1); ++d) {
                    const int64_t c = (a * dim[1] + b) * dim[2] + d;
                    // members sorted by index: skip to those above i
                    const int64_t* first = members.data() + start[c];
                    const int64_t* last = members.data() + start[c + 1];
                    for (const int64_t* p = std::upper_bound(first, last, i); p < last; ++p) {
                        const int64_t j = *p;
                        const double e0 = x[3 * j] - x[3 * i], e1 = x[3 * j + 1] - x[3 * i + 1], e2 = x[3 * j + 2] - x[3 * i + 2];
                        if (e0 * e0 + e1 * e1 + e2 * e2 < cut2) {
                            if (m < capacity) { pairs[2 * m] = i; pairs[2 * m + 1] = j; }
                            ++m;
                        }
                    }
                }
    }
    return m;
}
