"""Rendering for the Marbellous game: moderngl scenes, headless video, a pyglet window."""
