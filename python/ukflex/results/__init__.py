"""Reading results: the :class:`ukflex.SimulationResult` (:mod:`.simulation`), named outputs
(:mod:`.outputs`), sensors (:mod:`.sensors`), plots (:mod:`.plotting`) and animations
(:mod:`.animate`).
"""
