// Proleptic Gregorian dates <-> days since 1 January 1970 (Howard Hinnant's algorithms):
// report-step dates of restart files (paper Sec. 3: time steps) read and written.
#pragma once

#include <array>
#include <cstdint>

namespace resmr
{

/// Days since 1 January 1970 of year-month-day.
inline int64_t DaysFromCivil(int64_t year, int64_t month, int64_t day)
{
  year -= month <= 2;
  const int64_t era = (year >= 0 ? year : year - 399) / 400;
  const int64_t yearOfEra = year - era * 400;
  const int64_t dayOfYear = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const int64_t dayOfEra = yearOfEra * 365 + yearOfEra / 4 - yearOfEra / 100 + dayOfYear;
  return era * 146097 + dayOfEra - 719468;
}

/// Year, month, day of a count of days since 1 January 1970.
inline std::array<int, 3> CivilFromDays(int64_t days)
{
  days += 719468;
  const int64_t era = (days >= 0 ? days : days - 146096) / 146097;
  const int64_t dayOfEra = days - era * 146097;
  const int64_t yearOfEra = (dayOfEra - dayOfEra / 1460 + dayOfEra / 36524 - dayOfEra / 146096) / 365;
  const int64_t dayOfYear = dayOfEra - (365 * yearOfEra + yearOfEra / 4 - yearOfEra / 100);
  const int64_t shifted = (5 * dayOfYear + 2) / 153;
  const int64_t day = dayOfYear - (153 * shifted + 2) / 5 + 1;
  const int64_t month = shifted + (shifted < 10 ? 3 : -9);
  return { static_cast<int>(yearOfEra + era * 400 + (month <= 2)), static_cast<int>(month), static_cast<int>(day) };
}

} // namespace resmr
