"""The 3D viewport (navigation, tools, drawing through the renderer) and the shading panel that
chooses what it shows."""
