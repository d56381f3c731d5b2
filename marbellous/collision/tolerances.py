"""Fixed geometric constants of the narrow phase (dimensionless; part of the algorithms, not tunables).

- ``PARALLEL_SIN``: two features (capsule axis and capsule axis, capsule axis and box face) count as
  parallel when the sine of the angle between them is below this (about 2 degrees); parallel
  features in contact give a two-point manifold, which keeps a lying capsule from rocking.
- ``CROSS_AXIS_MIN``: an edge-edge axis ``e_a x e_b`` of the separating-axis test is skipped when
  ``|e_a x e_b|`` (unit edges) is below this; the face axes already cover parallel edges.
- ``FACE_BIAS``: the separating-axis test takes an edge axis (or the second shape's face) only when
  its separation beats the first shape's face by more than ``FACE_BIAS`` times the smallest half
  extent, so resting boxes keep the same reference face from step to step.
- ``CLIP_SLOP``: a face-clipping vertex that lies this fraction of the smallest half extent outside a
  side plane is kept, so boxes stacked edge on edge keep the same contact features.
"""

PARALLEL_SIN = 0.035
CROSS_AXIS_MIN = 1e-6
FACE_BIAS = 1e-3
CLIP_SLOP = 1e-9
