"""The stats line of the viewer and recorder: bodies, particles, cloths, contacts, time per step, simulated
time."""
from ..particles import Network


def stats_line(world, *, contacts, step_seconds=None, paused=False):
    """One line about ``world``: its bodies (how many static and asleep), its particles (how many pinned,
    and the edges of its networks, how many broken; left out when it has none), its cloths (their vertices,
    triangles and torn edges; left out when it has none), ``contacts`` (the number of contact points of the
    last step), ``step_seconds`` (wall-clock seconds per step; None leaves it out), the simulated time and
    whether the simulation is ``paused``."""
    bodies = world.bodies
    static = sum(b.is_static for b in bodies)
    kinematic = sum(b.is_kinematic for b in bodies)
    asleep = sum(not b.is_static and b.is_sleeping for b in bodies)
    kinds = f"{static} static, {kinematic} kinematic" if kinematic else f"{static} static"
    parts = [f"bodies {len(bodies)} ({kinds}, {asleep} asleep)"]
    particles = world.particles
    if particles:
        count = sum(len(p) for p in particles)
        pinned = sum(int(p.pinned.sum()) for p in particles)
        networks = [c for c in world.constraints if isinstance(c, Network)]
        line = f"particles {count} ({pinned} pinned"
        if networks:
            edges = sum(len(n) for n in networks)
            broken = sum(int(n.broken.sum()) for n in networks)
            line += f", {edges} edges, {broken} broken"
        parts.append(line + ")")
    cloths = world.cloths
    if cloths:
        vertices = sum(len(c) for c in cloths)
        triangles = sum(len(c.triangles) for c in cloths)
        torn = sum(c.torn for c in cloths)
        parts.append(f"cloths {len(cloths)} ({vertices} vertices, {triangles} triangles, {torn} torn)")
    parts.append(f"contacts {contacts}")
    if step_seconds is not None:
        parts.append(f"step {step_seconds * 1e3:.2f} ms")
    parts.append(f"t {world.time:.2f} s")
    if paused:
        parts.append("paused")
    return "  |  ".join(parts)
