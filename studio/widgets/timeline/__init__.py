"""The timeline: key poses over time, the pose sliders, playback and the timeline's undo
commands."""
