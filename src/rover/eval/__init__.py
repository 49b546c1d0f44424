"""Evaluation: traces + episodes -> metrics, in the paper's tables (Sec. 5, App. A, C, D, G-M).

`runner` drives `rover eval` (resumable, concurrent); `progress_metrics` (Task 1),
`rule_judge` / `judge` (Task 2), `qa` (Task 3), `cost`, `error_analysis`, `stratify` and
`aggregate` compute the numbers; `results` and `summary` write metrics.json / summary.md.
The run-directory layout is documented in docs/evaluation.md.
"""
