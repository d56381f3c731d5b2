"""The Marbellous game: levels, the marble, controls, the follow camera, the goal, the autopilot."""
