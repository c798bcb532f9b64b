"""Building a model: the scene builder (:mod:`.scene`), its coercion into plain data and the
core's checker (:mod:`.description`), scene files (:mod:`.scenefile`), the built-in scenes
(:mod:`.scenes`), flexible bodies from FE data (:mod:`.fe`, :mod:`.flexible`) and the compiled
system with its initial-state correction (:mod:`.system`).  Imports only the package's base
(``errors``, ``arguments``, ``_core``).
"""
