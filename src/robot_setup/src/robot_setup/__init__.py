"""Adding an arm: reach analysis and start pose (`analysis`, `collisions`), the robot-package generator
(`generate`, `templates`), the checker (`check`)."""
