"""flatcontact.analysis."""
