"""Input: a scene from TOML to validated frozen dataclasses.

``schema``    validation helpers and ``SceneError`` (one line naming the key)
``scene``     the scene dataclasses, built-in scenes and named cases, ``--set``
``geometry``  shapes, the lattice fill, the layer table
``loads``     initial conditions, boundary conditions, body-force loads
``scenes/``   the built-in scenes (TOML) and their named cases
"""
