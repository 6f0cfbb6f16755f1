"""Automatic set-up of a project from its poses: influence masks and WDVs from skin strain,
synthesised wrinkled maps, mirrored areas, and the face's own frame (up, front, symmetry)."""
