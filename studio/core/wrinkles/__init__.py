"""The two wrinkle techniques' data and formulas: technique 1's influence areas and masks
(painting, mirroring, composing), technique 2's wrinkle direction vectors, normal maps, relief,
skin strain and baking."""
