"""Run under ``mpiexec -n P python3 tests/mpi_partition_check.py``: a jittered lattice rod split
in z slabs between the ranks, solved by the partitioned solves and, whole, by the serial ones on
every rank (the test's reference only: the library's partitioned code sees only each rank's
share). Rank 0 prints one JSON line of the largest differences."""
import json
import os
import sys
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lattice import cubic_lattice  # noqa: E402

from yade_electro.network.conduction import ConductionProblem  # noqa: E402
from yade_electro.network.distributed import PartitionedConduction, PartitionedHeat  # noqa: E402
from yade_electro.network.heat_conditions import Convection, FixedTemperature  # noqa: E402
from yade_electro.network.kirchhoff import Electrode, edge_power  # noqa: E402
from yade_electro.network.partition import split_network  # noqa: E402
from yade_electro.network.transient import HeatSolver  # noqa: E402
from yade_electro.solvers.partitioned import mpi_comm  # noqa: E402

comm = mpi_comm()
rank, size = comm.Get_rank(), comm.Get_size()
shape = (6, 5, 40)
g = cubic_lattice(shape, r=1e-4)
rng = np.random.default_rng(3)
c = rng.uniform(0.5, 2.0, g.n_edges)
layer = shape[0] * shape[1]
n = g.n_nodes
bottom, top = np.arange(layer), np.arange(n - layer, n)
# a floating block: cut the edges of the last 2 nodes of layer 20 from everything
k = lattice_k = np.arange(n) // layer
float_nodes = np.array([20 * layer + 3, 20 * layer + 4])
cut = np.isin(g.edges[:, 0], float_nodes) ^ np.isin(g.edges[:, 1], float_nodes)
c[cut] = 0.0
keep = ~cut
edges, c = g.edges[keep], c[keep]
# owners: z slabs, with ranks' order scrambled (owner of a slab is not its index)
slab = np.minimum(k * size // shape[2], size - 1)
owner = (slab * 7 + 1) % size if size > 1 else slab
out = {"ranks": size}

# -- conduction -------------------------------------------------------------------------
with warnings.catch_warnings(record=True) as w_ser:
    warnings.simplefilter("always")
    serial = ConductionProblem(n, edges, c, [Electrode("a", bottom, potential=1.0), Electrode("b", top, potential=0.0)],
                               solver="direct")
    sol = serial.solve()
share, held = split_network(n, edges, owner, rank)
own = np.flatnonzero(owner == rank)
el = np.full(own.shape[0], -1)
el[np.isin(own, bottom)] = 0
el[np.isin(own, top)] = 1
for pc in ("deflation", "hypre", "gamg"):
    with warnings.catch_warnings(record=True) as w_par:
        warnings.simplefilter("always")
        pcnd = PartitionedConduction(share, c[held], el, ["a", "b"], {"a": 1.0, "b": 0.0}, comm=comm,
                                     preconditioner=pc, rtol=1e-12, pos=g.pos[own], spacing=2e-4)
        phi = pcnd.solve()
    d_phi = max(comm.allgather(float(np.max(np.abs(phi[:share.n_owned] - sol.potential[own]), initial=0.0))))
    R = pcnd.equivalent_resistance()
    I = pcnd.electrode_currents()
    P = pcnd.joule_power()
    p_edge = edge_power(sol.branch_current, c)
    P_ser = 0.5 * (np.bincount(edges[:, 0], p_edge, n) + np.bincount(edges[:, 1], p_edge, n))
    d_P = max(comm.allgather(float(np.max(np.abs(P - P_ser[own]), initial=0.0))))
    out[pc] = {"max_dphi_V": d_phi, "R_rel_diff": abs(R - sol.equivalent_resistance("a", "b")) /
               sol.equivalent_resistance("a", "b"),
               "I_a_rel_diff": abs(I["a"] - sol.electrode_current["a"]) / abs(sol.electrode_current["a"]),
               "I_sum": I["a"] + I["b"], "max_dP_rel": d_P / float(np.max(P_ser)),
               "iterations": pcnd.info["iterations"],
               "floating_warned": [str(x.message) for x in w_par][:1] if rank == 0 else None,
               "floating_ok": bool(np.all(phi[:share.n_owned][np.isin(own, float_nodes)] == 0.0))}
out["serial_floating_warned"] = [str(x.message) for x in w_ser][:1]

# -- values changed up to a hundredfold on the kept setup (the deflation's smoother and coarse
# factor are rebuilt when the iterations grow) ---------------------------------------------
c3 = c * np.exp(rng.uniform(np.log(0.01), np.log(100.0), c.size))
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    sol3 = ConductionProblem(n, edges, c3, [Electrode("a", bottom, potential=1.0), Electrode("b", top, potential=0.0)],
                             solver="direct").solve()
    pcnd = PartitionedConduction(share, c[held], el, ["a", "b"], {"a": 1.0, "b": 0.0}, comm=comm,
                                 preconditioner="deflation", rtol=1e-12, pos=g.pos[own], spacing=2e-4)
    pcnd.solve()
    pcnd.update_conductance(c3[held])
    phi = pcnd.solve()
d_phi = max(comm.allgather(float(np.max(np.abs(phi[:share.n_owned] - sol3.potential[own]), initial=0.0))))
out["changed"] = {"max_dphi_V": d_phi, "iterations": pcnd.info["iterations"], "setups": pcnd.info["setups"]}

# -- 'auto': the first solves try deflation, GAMG, BoomerAMG (2 each), the fastest is kept; every
# solve, trial or not, must be the serial answer -------------------------------------------
worst, picked = 0.0, []
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    pcnd = PartitionedConduction(share, c[held], el, ["a", "b"], {"a": 1.0, "b": 0.0}, comm=comm,
                                 preconditioner="auto", rtol=1e-12, pos=g.pos[own], spacing=2e-4)
    for k in range(8):
        ck = c * (1.0 + 0.01 * k)
        ck[::7] *= 1.0 + 0.05 * k                      # the values drift, the pattern holds
        ref = ConductionProblem(n, edges, ck, [Electrode("a", bottom, potential=1.0),
                                               Electrode("b", top, potential=0.0)], solver="direct").solve()
        pcnd.update_conductance(ck[held])
        phi = pcnd.solve()
        worst = max(worst, max(comm.allgather(float(np.max(np.abs(phi[:share.n_owned] - ref.potential[own]),
                                                           initial=0.0)))))
        picked.append(pcnd.info["preconditioner"])
out["auto"] = {"max_dphi_V": worst, "preconditioners": picked, "chosen": pcnd.info["chosen"]}

# -- links: an electrode apart from the elements (a wall), joined to the top layer; the links'
# values change on the kept structure, then their nodes change (a new structure) -------------
worst_link = {"phi": 0.0, "I": 0.0, "P": 0.0}
linked = [top[::2], top[::2], top[1::3]]                   # the third: other nodes touch the wall
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    pcnd = None
    for k, nodes in enumerate(linked):
        gl = 0.5 + 0.1 * k + 0.05 * np.arange(nodes.size)
        e_all = np.concatenate([edges, np.column_stack([nodes, np.full(nodes.size, n)])])
        c_all = np.concatenate([c, gl])
        ref = ConductionProblem(n + 1, e_all, c_all, [Electrode("a", bottom, potential=1.0),
                                                      Electrode("w", [n], potential=0.0)], solver="direct").solve()
        links = np.zeros((2, own.size))
        links[1, np.searchsorted(own, nodes[np.isin(nodes, own)])] = gl[np.isin(nodes, own)]
        el_a = np.where(np.isin(own, bottom), 0, -1)
        if pcnd is None or comm.allreduce(int(not pcnd.links_fit(links))):    # new linked nodes: anew
            if pcnd is not None:
                pcnd.close()
            pcnd = PartitionedConduction(share, c[held], el_a, ["a", "w"], {"a": 1.0, "w": 0.0}, comm=comm,
                                         preconditioner="deflation", rtol=1e-12, pos=g.pos[own], spacing=2e-4,
                                         links=links)
        pcnd.update_conductance(c[held], links)
        phi = pcnd.solve()
        I = pcnd.electrode_currents()
        p_ref = edge_power(ref.branch_current, c_all)
        m = edges.shape[0]
        P_ref = 0.5 * (np.bincount(edges[:, 0], p_ref[:m], n + 1) + np.bincount(edges[:, 1], p_ref[:m], n + 1))[:n]
        P_ref += np.bincount(nodes, p_ref[m:], n)            # a link's heat is its element's
        worst_link["phi"] = max(worst_link["phi"], max(comm.allgather(float(np.max(np.abs(
            phi[:share.n_owned] - ref.potential[own]), initial=0.0)))))
        worst_link["I"] = max(worst_link["I"], max(abs(I[t] - ref.electrode_current[t]) / abs(ref.electrode_current[t])
                                                   for t in ("a", "w")))
        worst_link["P"] = max(worst_link["P"], max(comm.allgather(float(np.max(np.abs(
            pcnd.joule_power() - P_ref[own]), initial=0.0)))) / float(np.max(P_ref)))
        worst_link["R_rel_diff"] = abs(pcnd.equivalent_resistance() - ref.equivalent_resistance("a", "w")) / \
            ref.equivalent_resistance("a", "w")
out["links"] = worst_link

# -- heat -----------------------------------------------------------------------------------
C = rng.uniform(1e-3, 2e-3, n)
G = c * 1e-2
hA = np.zeros(n)
side = np.flatnonzero(lattice_k == 10)
hA[side] = 3e-3
T0 = 300.0 + rng.uniform(0, 5, n)
Pw = rng.uniform(0, 1e-2, n)
for theta in (0.0, 0.5, 1.0):
    ser = HeatSolver(C, edges, G, T0, theta=theta, solver="direct",
                     conditions=[FixedTemperature("cold", nodes=bottom, temperature=290.0),
                                 Convection("side", nodes=side, h=1.0, t_inf=280.0, area=3e-3)])
    fixed = np.full(n, np.nan)
    fixed[bottom] = 290.0
    par = PartitionedHeat(share, C[own], G[held], T0[own], fixed=fixed[own], h_area=hA[own],
                          t_inf=np.full(own.shape[0], 280.0), theta=theta, comm=comm, rtol=1e-13,
                          pos=g.pos[own], spacing=2e-4)
    dt = 0.5 * par.stable_time_step() if theta == 0.0 else 0.05
    for _ in range(5):
        ser.advance(dt, sources=Pw)
        par.advance(dt, power=Pw[own])
    dT = max(comm.allgather(float(np.max(np.abs(par.T - ser.temperature[own]), initial=0.0))))
    out[f"heat_theta_{theta:g}"] = {"max_dT_K": dT, "dt_s": dt,
                                   "content_rel_diff": abs(par.heat_content(300.0) - float(C @ (ser.temperature - 300.0)))
                                   / abs(float(C @ (ser.temperature - 300.0)))}
# an isothermal wall (a linked fixed temperature) on the side layer, its links changing
from yade_electro.network.boundary import FixedValue  # noqa: E402
for theta in (0.0, 0.5, 1.0):
    wall_nodes = np.flatnonzero(lattice_k == 25)
    Gw = np.linspace(1e-3, 4e-3, wall_nodes.size)
    ser = HeatSolver(C, edges, G, T0, theta=theta, solver="direct",
                     conditions=[FixedTemperature("cold", nodes=bottom, temperature=290.0),
                                 FixedValue("wall", nodes=np.zeros(0, np.int64), value=350.0)],
                     nodes_of={"wall": wall_nodes}, link_of={"wall": Gw})
    fixed = np.full(n, np.nan)
    fixed[bottom] = 290.0
    par = PartitionedHeat(share, C[own], G[held], T0[own], fixed=fixed[own], theta=theta, comm=comm, rtol=1e-13,
                          pos=g.pos[own], spacing=2e-4, links={"wall": 350.0})
    Gw_all = np.zeros(n)
    dt = 0.5 * par.stable_time_step() if theta == 0.0 else 0.05
    for step in range(4):
        Gw_step = Gw * (1.0 + 0.3 * step)
        Gw_all[:] = 0.0
        Gw_all[wall_nodes] = Gw_step
        ser.set_links("wall", wall_nodes, Gw_step)
        par.set_links("wall", Gw_all[own])
        if theta == 0.0:
            dt = 0.5 * par.stable_time_step()
        ser.advance(dt, sources=Pw)
        par.advance(dt, power=Pw[own])
    dT = max(comm.allgather(float(np.max(np.abs(par.T - ser.temperature[own]), initial=0.0))))
    out[f"wall_theta_{theta:g}"] = {
        "max_dT_K": dT, "heat_rel_diff": abs(par.link_energy["wall"] - ser.link_energy["wall"]) /
        abs(ser.link_energy["wall"]), "flow_rel_diff": abs(par.link_flows()["wall"] - ser.link_flows()["wall"]) /
        abs(ser.link_flows()["wall"])}
# the heat step with 'auto': backward Euler, 8 steps (deflation, GAMG, BoomerAMG twice each, the choice)
ser = HeatSolver(C, edges, G, T0, theta=1.0, solver="direct",
                 conditions=[FixedTemperature("cold", nodes=bottom, temperature=290.0),
                             Convection("side", nodes=side, h=1.0, t_inf=280.0, area=3e-3)])
fixed = np.full(n, np.nan)
fixed[bottom] = 290.0
par = PartitionedHeat(share, C[own], G[held], T0[own], fixed=fixed[own], h_area=hA[own],
                      t_inf=np.full(own.shape[0], 280.0), theta=1.0, comm=comm, rtol=1e-13,
                      pos=g.pos[own], spacing=2e-4, preconditioner="auto")
for _ in range(8):
    ser.advance(0.05, sources=Pw)
    par.advance(0.05, power=Pw[own])
out["heat_auto"] = {"max_dT_K": max(comm.allgather(float(np.max(np.abs(par.T - ser.temperature[own]), initial=0.0)))),
                    "chosen": par.info.get("chosen")}
if rank == 0:
    print(json.dumps(out), flush=True)
