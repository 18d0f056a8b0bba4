"""User interfaces (CLI, later the app). They hold no physics."""
