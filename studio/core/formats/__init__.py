"""Foreign formats in and out: one module (or small package) per format with its reader and
writer side by side — glTF and VRM, FBX, USD, capture weights, the export folder and its
Blender material script, the web page — plus assembling a project from such files. They share
the budgets and error vocabulary of `studio.core.files` and build `studio.core.project` models."""
