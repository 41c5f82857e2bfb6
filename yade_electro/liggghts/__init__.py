"""LIGGGHTS adapter of yade-electro (data files, deck rendering from ``liggghts_templates/``,
runner, dump parser). Not written yet: the tests only check that ``liggghts`` runs."""
