"""flatcontact.potentials."""
