"""The run directory as one typed artifact: models, one reader/writer, the scorer.

`rover eval` writes a run directory; `rover.run.scorer` turns its files into metrics once;
`rover report`, `rover demo`, the terminal table and the CSV exports only read them
through `rover.run.store.RunStore`. Nothing here imports the report, so every view can
import this package without cycles.
"""

SCHEMA_VERSION = 2
