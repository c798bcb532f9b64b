"""What a compiled system tells besides its motion: natural frequencies and modes, static
equilibrium, rank and conditioning reports, and the diagnostics of runs (:mod:`.stability`,
public as ``ukflex.stability``).
"""
