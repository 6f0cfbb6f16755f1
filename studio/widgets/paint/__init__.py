"""Technique 1 in the GUI: influence areas, painting masks on the UV canvas and on the face, and the
undo commands of a stroke."""
