"""Key poses and their animation: pose blending, the timeline's keyed weight curves, and the
ARKit pose names in every spelling."""
