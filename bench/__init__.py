"""Benchmarks of Marbellous, side by side with PyBullet and MuJoCo (``python -m bench``)."""
