"""The face mesh and what is computed on it: geometry (normals, tangents), mesh files, UDIM tiles,
the camera, picking and selection, the face's regions."""
