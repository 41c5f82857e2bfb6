"""Results after a solve: probes, sections and gradients, VTK files, plots, torsion statistics
and the gathering of yade-batch campaigns.
"""
from .probes import (ProbeError, ProbeValues, probe, line_probe, plane_probe, section_mean, region_mean,
                     slab_means, element_gradients)
from .torsion import (polar_moment, elastic_torque, surface_shear_stress, yield_angle, elastic_slope,
                      first_crossing, ratio_at, crack_summary)
from .vtk import write_elements, write_bonds

__all__ = ["ProbeError", "ProbeValues", "probe", "line_probe", "plane_probe", "section_mean", "region_mean",
           "slab_means", "element_gradients", "polar_moment", "elastic_torque", "surface_shear_stress",
           "yield_angle", "elastic_slope", "first_crossing", "ratio_at", "crack_summary", "write_elements",
           "write_bonds"]
