"""flatcontact.training."""
