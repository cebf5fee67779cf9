"""What every planner of the package stands on: parameter tables, the planner base, state
points, trees and their scans, and the counting of work (see docs/architecture.md)."""
