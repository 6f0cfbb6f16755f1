"""glTF 2.0 (and the GLB container VRM uses): `codec` reads and writes a project, the other
modules hold one part each — the container, the scene's meshes, the face chosen among them, its
materials, the animation, and the studio's set-up carried in the file."""
