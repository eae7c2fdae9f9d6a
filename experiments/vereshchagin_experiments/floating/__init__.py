"""Floating and mobile bases in the main job (issue 28): a Gen3 on a holonomic base (:mod:`.mobile`)."""
