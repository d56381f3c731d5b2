"""The application layer: the game's window and demo, the viewer, the gymnasium environments.  Nothing
below it imports it."""
