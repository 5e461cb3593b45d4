"""fastcontact.studies."""
