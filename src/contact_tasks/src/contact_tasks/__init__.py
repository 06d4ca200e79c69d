"""Contact tasks: task files (`task_file`), motion patterns (`patterns`) and the executor's logic (`run`);
see the package README."""
