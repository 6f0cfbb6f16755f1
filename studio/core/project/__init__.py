"""One project: the model tying mesh, poses, textures, areas and timeline together, its file
(schema, reader, writer, migrations), glTF, assembling from files, export, the sample face and
the view settings saved with it."""
