"""flatcontact.plots."""
