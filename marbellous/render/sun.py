"""The sun of the game's pictures (``renderer.py``): their one light, and the side the goal's flag turns its
face to (``game/flag.py``: a flag edge-on to the light reads as a dark sliver).  Plain NumPy, so the game
reads it without the rendering packages."""
import numpy as np

#: Unit vector towards the sun.
SUN = np.array([0.45, 0.8, 0.35]) / np.linalg.norm([0.45, 0.8, 0.35])
