"""numpy forms of the compiled kernels, kept only as the tests' references (the package runs
the kernels built at install). Each is the kernel's algorithm written with numpy's array
operations; the tests compare the two on the same inputs."""
import numpy as np

from yade_electro.core.errors import MaterialError
from yade_electro.geometry.contacts import quaternion_matrices
from yade_electro.laws.transmission import edge_transmission_surface


def facet_vertices(pos, quat, local):
    """World vertices (k, 3, 3) of rigid triangles: ``pos + R(quat) local``."""
    R = quaternion_matrices(quat)
    return np.asarray(pos, float)[:, None, :] + np.einsum("kij,kvj->kvi", R, np.asarray(local, float))


def triangle_distance(points, triangles) -> np.ndarray:
    """Distance from each point to the triangle of the same row (Ericson 5.1.5)."""
    p = np.asarray(points, float)
    t = np.asarray(triangles, float)
    a, b, c = t[:, 0], t[:, 1], t[:, 2]
    ab, ac, ap = b - a, c - a, p - a

    def dot(u, v):
        return np.einsum("ij,ij->i", u, v)
    d1, d2 = dot(ab, ap), dot(ac, ap)
    bp = p - b
    d3, d4 = dot(ab, bp), dot(ac, bp)
    cp = p - c
    d5, d6 = dot(ab, cp), dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v = vb / denom
        w = vc / denom
        q = a + v[:, None] * ab + w[:, None] * ac                  # inside the face
        # edges
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    on_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
    on_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
    on_bc = (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0)
    q = np.where(on_bc[:, None], b + t_bc[:, None] * (c - b), q)
    q = np.where(on_ac[:, None], a + t_ac[:, None] * ac, q)
    q = np.where(on_ab[:, None], a + t_ab[:, None] * ab, q)
    # corners
    q = np.where(((d6 >= 0) & (d5 <= d6))[:, None], c, q)
    q = np.where(((d3 >= 0) & (d4 <= d3))[:, None], b, q)
    q = np.where(((d1 <= 0) & (d2 <= 0))[:, None], a, q)
    return np.sqrt(((p - q) ** 2).sum(axis=1))




def edge_lengths(graph, edges):
    """Centre distances of node pairs (the graph's periodic shifts applied)."""
    d = graph.edge_vectors(np.asarray(edges, dtype=np.int64).reshape(-1, 2))
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    if np.any(length <= 0):
        raise MaterialError("two connected elements have coincident centres (l_ij = 0)")
    return length


def contact_radius(graph, edges=None, model="geometric"):
    """The lens radius (``'geometric'``) or the Hertz radius of each pair, 0 apart."""
    edges = graph.edges if edges is None else np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    r1, r2 = graph.radius[edges[:, 0]], graph.radius[edges[:, 1]]
    d = edge_lengths(graph, edges)
    if model == "hertz":
        return np.sqrt(r1 * r2 / (r1 + r2) * np.clip(r1 + r2 - d, 0.0, None))
    x = (r1 ** 2 - r2 ** 2 + d ** 2) / (2.0 * d)
    a2 = np.where(d < r1 + r2, r1 ** 2 - x ** 2, 0.0)
    return np.sqrt(np.clip(a2, 0.0, None))


def continuum_factor(graph, threshold=0.4, factor=2.0):
    """Paper 000's g = sqrt(S_i S_j) / l_ij on the bonds."""
    return edge_transmission_surface(graph, threshold=threshold, factor=factor) / edge_lengths(graph, graph.edges)


def hops_linked(n, bonds, pairs, hops):
    """Per pair: are its two nodes linked by at most ``hops`` bonds? (powers of the adjacency)"""
    import scipy.sparse as sp
    b = np.asarray(bonds, dtype=np.int64).reshape(-1, 2)
    adj = sp.coo_matrix((np.ones(len(b)), (b[:, 0], b[:, 1])), shape=(n, n))
    adj = (adj + adj.T + sp.identity(n)).tocsr()
    reach = adj
    for _ in range(int(hops) - 1):
        reach = (reach @ adj).tocsr()
        reach.data[:] = 1.0
    return np.asarray(reach[pairs[:, 0], pairs[:, 1]]).ravel() > 0
