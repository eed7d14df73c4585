"""The DAG task engine: what is ready (graph iteration) apart from how tasks run (executors)."""
