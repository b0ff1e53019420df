"""flatcontact.structures."""
