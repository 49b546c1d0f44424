"""`rover annotate`: a method's per-frame output for a whole dataset, as parquet tables.

Researchers curate robot data with progress estimators: weight frames by progress for
training (LeRobot's SARM writes `sarm_progress.parquet` beside a dataset), or rank
episodes by VOC to find failed demonstrations (GVL). `run_annotate` runs one method over
every episode of any source and writes what it said, frame by frame and episode by
episode; `rover.annotate.tables` holds the table layouts.
"""

from rover.annotate.runner import AnnotateOptions, plan_annotation, run_annotate

__all__ = ["AnnotateOptions", "plan_annotation", "run_annotate"]
