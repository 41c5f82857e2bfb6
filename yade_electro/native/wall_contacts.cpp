// Sphere-triangle distances of the granular mode's facet walls (yade_electro.contacts), compiled:
// the closest point of a triangle (Ericson, Real-Time Collision Detection, 5.1.5, the same
// regions and precedence as contacts.triangle_distance's numpy form: corner a, b, c, then edges
// ab, ac, bc, then the face), and the candidate (sphere, triangle) pairs of a Verlet list.
//
// points (k, 3), triangles (k, 3, 3) row-major float64.
#include <cmath>
#include <cstdint>

namespace {

inline double dot3(const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; }

double distance(const double* p, const double* t) {
    const double* a = t;
    const double* b = t + 3;
    const double* c = t + 6;
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
    for (int k = 0; k < 3; ++k) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
        bp[k] = p[k] - b[k];
        cp[k] = p[k] - c[k];
    }
    const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    const double va = d3 * d6 - d5 * d4;
    const double vb = d5 * d2 - d1 * d6;
    const double vc = d1 * d4 - d3 * d2;
    if (d1 <= 0 && d2 <= 0) {
        for (int k = 0; k < 3; ++k) q[k] = a[k];
    } else if (d3 >= 0 && d4 <= d3) {
        for (int k = 0; k < 3; ++k) q[k] = b[k];
    } else if (d6 >= 0 && d5 <= d6) {
        for (int k = 0; k < 3; ++k) q[k] = c[k];
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double s = d1 / (d1 - d3);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + s * ab[k];
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double s = d2 / (d2 - d6);
        for (int k = 0; k < 3; ++k) q[k] = a[k] + s * ac[k];
    } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; ++k) q[k] = b[k] + s * (c[k] - b[k]);
    } else {
        const double denom = va + vb + vc;
        const double v = vb / denom, w = vc / denom;
        for (int k = 0; k < 3; ++k) q[k] = a[k] + v * ab[k] + w * ac[k];
    }
    const double e0 = p[0] - q[0], e1 = p[1] - q[1], e2 = p[2] - q[2];
    return std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
}

}  // namespace

// out[i] = distance from points[i] to triangles[i].
extern "C" void wall_triangle_distance(int64_t k, const double* points, const double* triangles, double* out) {
    for (int64_t i = 0; i < k; ++i) out[i] = distance(points + 3 * i, triangles + 9 * i);
}

// The (sphere, triangle) pairs with distance < radius[i] + skin, among those whose centre is
// within reach[t] (the triangle's bounding ball radius + the largest sphere radius + skin) of the
// triangle's ball centre; sorted by sphere, then triangle. Returns their count (written only up
// to capacity: call again with more room).
extern "C" int64_t wall_triangle_candidates(int64_t n, const double* pos, const double* radius, double skin,
                                            int64_t ntri, const double* triangles, const double* centre,
                                            const double* reach, int64_t capacity, int64_t* spheres,
                                            int64_t* pieces) {
    int64_t m = 0;
    for (int64_t i = 0; i < n; ++i) {
        const double* p = pos + 3 * i;
        for (int64_t t = 0; t < ntri; ++t) {
            const double* c = centre + 3 * t;
            const double e0 = p[0] - c[0], e1 = p[1] - c[1], e2 = p[2] - c[2];
            if (e0 * e0 + e1 * e1 + e2 * e2 > reach[t] * reach[t]) continue;
            if (distance(p, triangles + 9 * t) < radius[i] + skin) {
                if (m < capacity) {
                    spheres[m] = i;
                    pieces[m] = t;
                }
                ++m;
            }
        }
    }
    return m;
}

// World vertices of k rigid triangles (YADE facets): out[t, v] = pos[t] + R(quat[t]) local[t, v],
// R the rotation matrix of the unit quaternion (x, y, z, w) as contacts.quaternion_matrices
// writes it, the products summed over j = 0, 1, 2 in turn. pos (k, 3), quat (k, 4), local and
// out (k, 3, 3).
extern "C" void wall_facet_vertices(int64_t k, const double* pos, const double* quat, const double* local,
                                    double* out) {
    for (int64_t t = 0; t < k; ++t) {
        const double x = quat[4 * t], y = quat[4 * t + 1], z = quat[4 * t + 2], w = quat[4 * t + 3];
        const double R[3][3] = {
            {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
        const double* p = pos + 3 * t;
        for (int v = 0; v < 3; ++v) {
            const double* l = local + 9 * t + 3 * v;
            double* o = out + 9 * t + 3 * v;
            for (int i = 0; i < 3; ++i) o[i] = p[i] + (R[i][0] * l[0] + R[i][1] * l[1] + R[i][2] * l[2]);
        }
    }
}
