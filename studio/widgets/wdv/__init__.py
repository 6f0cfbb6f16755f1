"""Technique 2 in the GUI: the wrinkle vectors panel, vertex selection in the viewport and the undo
commands that create and edit WDV areas."""
