"""What technique 2 and the automatic mode measure when poses have onsets.

Both read the face's motion, not the pose weights: technique 2 the vertex's displacement from
the neutral (``in_position - in_rest`` in shaders/face.vert), the automatic mode the compression
of the skin's edges. A pose's onset (``FurrowControls.onset``) delays its lines along its
weight without delaying its shape, so the wrinkles measure another face: the *drive*, blended
with each weight through its pose's onset (``Project.wrinkle_weights``), while the face drawn
keeps the real weights.

Technique 2 gets it with no change to its shader: the rest position it subtracts is moved by
what the drive lacks of the face (``rest + positions - drive``), so the displacement it
measures is the drive's. The automatic mode's weights are the numpy reference's
(``StrainField.weights``) of the drive. With no onset (every project made before them) there is
no drive: the rest stays the neutral and the deform pass measures the strain, exactly as before.
"""

from __future__ import annotations

import numpy as np

from studio.core.mesh.face_mesh import FaceMesh
from studio.core.wrinkles.strain import StrainField

Array = np.ndarray


class WrinkleDrive:
    """The drive of one mesh (None: the face itself), as per-render-vertex inputs."""

    def __init__(self, mesh: FaceMesh) -> None:
        self.mesh = mesh
        self.drive: Array | None = None  # (W, 3) welded positions the wrinkles measure
        self.version = 0  # counts changes: what the strain weights are kept for
        self._strain: StrainField | None = None  # the mesh's edges (on first use)

    @property
    def active(self) -> bool:
        return self.drive is not None

    def set(self, positions: Array | None, drive: Array | None) -> Array:
        """This frame's face (welded ``positions``) and drive, or None for both when no pose
        has an onset; returns the rest position technique 2 subtracts, per render vertex."""
        self.version += 1
        rest = self.mesh.rest
        if positions is None or drive is None:
            self.drive = None
            return rest[self.mesh.weld].astype(np.float32)
        self.drive = np.array(drive, dtype=np.float64)
        return (rest + (np.asarray(positions, np.float64) - self.drive))[self.mesh.weld] \
            .astype(np.float32)

    def strain(self, full_at: float) -> Array:
        """The automatic mode's weight per render vertex, measured on the drive."""
        if self._strain is None:
            self._strain = StrainField(self.mesh)
        return self._strain.weights(self.drive, full_at)[self.mesh.weld].astype(np.float32)
