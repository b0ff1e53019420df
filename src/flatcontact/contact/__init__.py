"""flatcontact.contact."""
