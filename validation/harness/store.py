"""Engine outputs collected during the session (for the figures written at the end)."""
ENGINE: dict = {}   # (case name, run label) -> EngineResult
FMU: dict = {}      # case name -> FmuRun (fmpy)
