"""Reading results: the :class:`ukflex.SimulationResult` (:mod:`.simulation`), named outputs
(:mod:`.outputs`), sensors (:mod:`.sensors`), plots (:mod:`.plotting`), animations
(:mod:`.animate`), the fields of modal bodies (:mod:`.fields`) and the VTK export for ParaView
(:mod:`.vtk`).
"""
