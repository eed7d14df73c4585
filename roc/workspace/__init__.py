"""The workspace model: discovery, identification, manifests, dependency graph, selection."""
