"""Where torch runs for the Blender extension: a worker process speaking JSON lines
(``server``, ``python -m shapemove worker``), its client (``client.WorkerClient``) and the same
jobs in a thread of the current process (``client.InProcessRunner``).

Modules: protocol (message schema), ops (the job registry JOBS), runner (one job at a time with
progress/cancel), server (stdin/stdout loop), client (process management, no bpy).
"""
