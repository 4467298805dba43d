"""Off-screen videos of episodes: ``video.render(replay, "episode.mp4", options)``.

- ``options``: ``VideoOptions`` (size, fps, camera, frames per control step), output checks.
- ``replay``: ``Replay`` (an episode and the environment it ran in) and its step-by-step replay.
- ``scene``: the robot's MJCF plus floor, lights, sky and cameras framing the episode.
- ``markers``: target trail, achieved tip path and caption drawn into each frame.
- ``frames``: frames of a replay in this process (``MUJOCO_GL`` as dm_control loaded it).
- ``video``: renders in a child process per OpenGL backend (egl, then osmesa) to MP4 or frames.
- ``worker``: that child process.

This package imports nothing on import, so that the worker can choose its OpenGL backend
before dm_control loads.
"""
