"""Running a model: :func:`ukflex.simulate` and its scipy and native drivers (:mod:`.simulate`),
the automatic method choice (:mod:`.choice`) and parameter sweeps (:mod:`.sweep`).
"""
