"""Rendering with moderngl: the game's level renderer, a renderer of any World with its drawables, headless video."""
