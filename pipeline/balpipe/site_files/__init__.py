"""The site's files on disk: which specs a build reads and their page names, the pages of earlier
builds, and what checking a spec costs."""
