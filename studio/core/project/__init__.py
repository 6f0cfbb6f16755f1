"""One project and its file: the model tying mesh, poses, textures, areas and timeline together,
the file's schema, reader, writer and migrations, the mask store and the view settings saved with
it. Foreign formats (glTF, VRM, FBX, USD, exports) live in `studio.core.formats` and depend on
this package, never the other way round; the bundled sample lives in `studio.core.sample`."""
