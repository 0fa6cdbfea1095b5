"""The hardware feature matcher (issue 29): the match engine and, around it, the corners' descriptors."""
