"""The content store (keys from values and code, atomic entries in ``reports/.cache/``) and its
users: balancing searches, simulations and figures, each cached by the content of its inputs."""
