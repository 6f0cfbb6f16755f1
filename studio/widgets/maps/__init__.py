"""Wrinkled maps: loading, baking from a high-poly mesh, and the automatic set-up tools."""
