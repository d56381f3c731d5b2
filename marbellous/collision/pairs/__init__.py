"""Pair tests of primitive shapes, ``collide_<a>_<b>`` with the fixed order sphere < capsule < box <
plane, and the dispatcher that flips pairs so that normals point from a to b."""
