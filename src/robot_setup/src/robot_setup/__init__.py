"""Adding an arm: reach analysis and start pose (`analysis`, `collisions`), the robot-package generator
(`generate`, `plan`, `templates`), the checker (`check`)."""
