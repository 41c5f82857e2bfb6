"""LIGGGHTS adapter of yade-electro: data files (:mod:`.datafile`), decks rendered from the
templates in ``liggghts_templates/`` (:mod:`.deck`), the runner (:mod:`.runner`), dump
parsers to pandas (:mod:`.dumps`), heat-conduction runs (:mod:`.heat`) and packings made in
LIGGGHTS (:mod:`.settling`). It never imports YADE; ``yade_electro.yade.spheres`` puts an
imported packing into a YADE scene."""
from .datafile import ParticleData, format_data, particle_data, read_data, write_data
from .deck import (TEMPLATE_DIR, CylinderWall, GranularMaterial, MeshWall, PlaneWall, material_commands,
                   pair_local_columns, render_deck, size_class_commands, template_names, temperature_commands,
                   wall_commands)
from .dumps import DumpFrame, read_dump, read_dump_frames
from .settling import BlockRegion, CylinderRegion, SettledPacking, settle_deck, settle_packing
from .heat import HEAT_PAIR_KEYWORDS, HeatDeck, HeatRunResult, heat_conduction_deck, run_heat_conduction
from .runner import LiggghtsError, LiggghtsNotFound, LiggghtsRun, find_liggghts, mpi_command, run_deck

__all__ = [
    "ParticleData", "particle_data", "format_data", "write_data", "read_data",
    "TEMPLATE_DIR", "template_names", "render_deck", "GranularMaterial", "PlaneWall", "CylinderWall", "MeshWall",
    "material_commands", "wall_commands", "temperature_commands", "size_class_commands", "pair_local_columns",
    "DumpFrame", "read_dump", "read_dump_frames",
    "HEAT_PAIR_KEYWORDS", "HeatDeck", "HeatRunResult", "heat_conduction_deck", "run_heat_conduction",
    "LiggghtsError", "LiggghtsNotFound", "LiggghtsRun", "find_liggghts", "mpi_command", "run_deck",
    "CylinderRegion", "BlockRegion", "SettledPacking", "settle_deck", "settle_packing",
]
