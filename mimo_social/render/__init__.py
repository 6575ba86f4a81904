"""All OpenGL: the headless backend, the eye tile renderer, the scene renderer; and PNG files."""
