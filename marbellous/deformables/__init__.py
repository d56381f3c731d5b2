"""Deformable matter: particles and the networks of springs, rods and cables between them.

Their own tables and their own compiled stage, run after the rigid bodies' step and only in worlds that have
particles, so that no other world compiles or pays for them."""
