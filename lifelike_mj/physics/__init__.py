"""Physics shared by all creatures: fluid forces (pure functions) and MuJoCo plumbing."""
