"""The colours of a drawn world: what each kind and state of body, and each debug layer, looks like.

Colours are linear RGB in [0, 1].  A body's colour says what it is at a glance: stone grey for static
bodies, violet for kinematic ones, warm hues (orange, coral, amber, gold, in turn by body) for moving
dynamic bodies, slate blue for sleeping ones and translucent green for sensors.  Particles are teal, pinned
ones raspberry; cloth is chartreuse; fluids are blues.  The debug layers use colours no body has: yellow contacts, cyan
bounding boxes, magenta springs, white rods and brown cables (of bodies and of particle networks alike).
"""
import numpy as np

#: Background (clear colour) of the viewer, and the colour distant geometry fades into.
BACKGROUND = (0.16, 0.18, 0.22)
#: Static bodies: stone grey (drawn with a grid that shows the scale).
STATIC = (0.62, 0.62, 0.60)
#: Kinematic bodies (moved by their velocities): violet, drawn with the static bodies' grid.
KINEMATIC = (0.58, 0.36, 0.78)
#: Moving dynamic bodies, by body index in turn: warm hues, so neighbours in a stack stand apart.
DYNAMIC = np.array([(0.93, 0.45, 0.13), (0.90, 0.30, 0.24), (0.95, 0.62, 0.16), (0.86, 0.52, 0.30),
                    (0.92, 0.38, 0.10), (0.97, 0.72, 0.25)])
#: Sleeping dynamic bodies, by body index in turn: slate blues.
SLEEPING = np.array([(0.38, 0.46, 0.72), (0.30, 0.38, 0.62), (0.45, 0.52, 0.78)])
#: Sensors (any kind): green, drawn translucent with opacity :data:`SENSOR_ALPHA`.
SENSOR = (0.30, 0.90, 0.42)
#: Opacity of sensors, in [0, 1].
SENSOR_ALPHA = 0.35
#: Particles (any set), and particles pinned to the world or to a body.
PARTICLE = (0.10, 0.66, 0.64)
PINNED_PARTICLE = (0.86, 0.10, 0.34)
#: Cloth (any cloth, both faces): chartreuse, green over red well over blue (no body, particle or overlay has it).
CLOTH = (0.56, 0.78, 0.12)
SOFT_BODY = (0.93, 0.45, 0.62)
#: Fluids: the box's edges and the surface line (deep blue), velocity arrows from slow (blue) to fast (white),
#: and dye (smoke, ink) as puffs, pale to deep azure by amount.
FLUID_BOX = (0.20, 0.45, 0.95)
FLUID_SLOW = (0.15, 0.35, 0.95)
FLUID_FAST = (0.95, 0.97, 1.00)
DYE_THIN = (0.75, 0.88, 1.00)
DYE_THICK = (0.10, 0.45, 0.95)
#: Contact points and their normals.
CONTACT = (1.0, 0.88, 0.10)
#: Contact events of the last step: pairs that began touching (red), and that stopped (pale blue).
EVENT_BEGIN = (1.0, 0.20, 0.15)
EVENT_END = (0.55, 0.75, 1.0)
#: Broad-phase bounding boxes.
BOX = (0.15, 0.90, 1.0)
#: Constraint lines by kind, and their anchor points; the edges of particle networks by kind too.
SPRING = (0.95, 0.25, 0.85)
ROD = (0.96, 0.96, 0.96)
CABLE = (0.62, 0.40, 0.20)
#: joints: the arms from each body's centre to the joint, and the hinge's or slider's axis
JOINT = (1.00, 0.80, 0.10)
JOINT_AXIS = (0.20, 0.90, 1.00)


def body_color(index, *, static, sleeping, sensor, kinematic=False):
    """RGB colour (3,) of the body at ``index`` (its creation order) in the given state."""
    if sensor:
        return np.array(SENSOR)
    if static:
        return np.array(STATIC)
    if kinematic:
        return np.array(KINEMATIC)
    if sleeping:
        return SLEEPING[index % len(SLEEPING)].copy()
    return DYNAMIC[index % len(DYNAMIC)].copy()
